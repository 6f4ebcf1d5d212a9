"""The reviewer's workstation in headless Chromium, on real takes of the corpus.

Each test drives the page the way a reviewer would (mouse drags, key presses, clicks) and checks
that the page keeps answering. Time bounds are generous (a loaded 2-core machine must pass);
the figures measured on the way are written to ``tests/artifacts/workstation-timings.json`` and
the screenshots to ``tests/artifacts/`` (gitignored).
"""

from __future__ import annotations

import io
import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import numpy as np
import pytest
from PIL import Image

pytestmark = pytest.mark.browser

ARTIFACTS = Path(__file__).resolve().parents[1] / "artifacts"
KNEES_TAKE = "bvh/cmu/iclone/005_05.bvh"  # 100 joints, real knee twist errors
TRC_TAKE = (
    "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
)
ANSWER_S = 5.0  # "the page still answers": a round trip far above 100 ms, far below a freeze
TIMINGS: dict[str, Any] = {}


def upload(server: str, path: Path) -> dict[str, Any]:
    """Upload a take through the API and wait for its first run."""
    with path.open("rb") as stream:
        created = httpx.post(
            f"{server}/api/v1/takes", files={"file": (path.name, stream)}, timeout=120
        )
    created.raise_for_status()
    take = created.json()
    wait_for_run(server, take["run_id"], path.name)
    result = httpx.get(f"{server}/api/v1/runs/{take['run_id']}/result", timeout=30).json()
    return {"id": take["id"], "run": take["run_id"], "result": result}


def wait_for_run(server: str, run_id: str, what: str = "the run") -> None:
    """Wait until a run ends (at most 5 minutes, a deadline for a stuck run, not a speed
    test) and check it is done."""
    deadline = time.monotonic() + 300
    while True:
        run = httpx.get(f"{server}/api/v1/runs/{run_id}", timeout=30).json()
        if run["status"] in ("done", "failed"):
            break
        if time.monotonic() > deadline:
            raise TimeoutError(f"analysis of {what} did not finish")
        time.sleep(0.3)
    assert run["status"] == "done", run


def run_again(server: str, take_id: str, options: dict[str, Any]) -> str:
    """Start a run of a take with ``options`` through the API, wait for it; its id."""
    created = httpx.post(f"{server}/api/v1/takes/{take_id}/runs", json=options, timeout=30)
    created.raise_for_status()
    run_id: str = created.json()["id"]
    wait_for_run(server, run_id)
    return run_id


@pytest.fixture(scope="module")
def takes(live_server: str, corpus_dir: Path) -> dict[str, dict[str, Any]]:
    return {
        "knees": upload(live_server, corpus_dir / KNEES_TAKE),
        "trc": upload(live_server, corpus_dir / TRC_TAKE),
    }


@pytest.fixture(scope="module", autouse=True)
def write_timings() -> Iterator[None]:
    yield
    ARTIFACTS.mkdir(exist_ok=True)
    (ARTIFACTS / "workstation-timings.json").write_text(json.dumps(TIMINGS, indent=2))


class Page:
    """A Playwright page that records console errors."""

    def __init__(self, chromium: Any, width: int = 1400, height: int = 1000) -> None:
        self.page = chromium.new_page(viewport={"width": width, "height": height})
        self.errors: list[str] = []
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))

    def open_take(self, server: str, take: dict[str, Any], frame: int | None = None) -> None:
        query = f"?run={take['run']}" + (f"&frame={frame}" if frame is not None else "")
        self.page.goto(f"{server}/#/take/{take['id']}{query}")
        self.page.wait_for_selector("main[data-ready='1']", timeout=60_000)
        self.settle()

    def settle(self) -> None:
        """Wait until the 3D views have drawn what was asked and the page painted twice."""
        self.page.wait_for_function(
            "() => window.mocapqaViews && !window.mocapqaViews.busy", timeout=30_000
        )
        self.page.evaluate(
            "() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))"
        )

    def answers_within(self) -> float:
        """Seconds the page takes to run a script and paint (raises when frozen)."""
        start = time.monotonic()
        self.page.wait_for_function("() => true", timeout=ANSWER_S * 4 * 1000, polling="raf")
        return time.monotonic() - start

    def frame(self) -> int:
        return int(self.page.inner_text("#frame-label").split()[1])

    def close(self) -> None:
        assert self.errors == []
        self.page.close()


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def scrub(page: Page, frame: int) -> None:
    page.page.evaluate(
        "(f) => { const s = document.getElementById('scrubber'); s.value = f;"
        " s.dispatchEvent(new Event('input')); s.dispatchEvent(new Event('change')); }",
        frame,
    )
    page.settle()


def drag_camera(page: Page, selector: str) -> None:
    """Drag the mouse across the middle of a 3D view in 12 moves (an orbit of its camera)."""
    box = page.page.locator(selector).bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.page.mouse.move(x, y)
    page.page.mouse.down()
    for step in range(1, 13):
        page.page.mouse.move(x + 12 * step, y + 3 * step)
    page.page.mouse.up()


def view_pixels(page: Page, selector: str) -> np.ndarray:
    png = page.page.locator(selector).screenshot()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


def test_dragging_either_camera_keeps_the_page_answering(
    live_server: str, takes: dict[str, Any], page: Page
) -> None:
    page.open_take(live_server, takes["knees"])
    # The open mode's header: who, and no sign-out (nothing else, not a stray "null").
    assert page.page.inner_text("#whoami") == "anonymous (admin)"
    assert page.page.locator("#sign-out").count() == 0
    assert "null" not in page.page.text_content("#account")
    answers = []
    orbits = [page.page.evaluate("() => window.mocapqaViews.orbit")]
    for view in ("#view-raw", "#view-corrected"):
        drag_camera(page, view)
        answers.append(page.answers_within())
        assert answers[-1] < ANSWER_S
        # A button still works at once after the drag.
        page.page.click("#show-axes", timeout=ANSWER_S * 1000)
        assert page.page.is_checked("#show-axes")
        page.page.click("#show-axes", timeout=ANSWER_S * 1000)
        page.settle()
        orbits.append(page.page.evaluate("() => window.mocapqaViews.orbit"))
    # Each drag turned the one camera both views are drawn with.
    assert orbits[1]["azimuth"] != pytest.approx(orbits[0]["azimuth"])
    assert orbits[2]["azimuth"] != pytest.approx(orbits[1]["azimuth"])
    # Once the mouse is up nothing redraws: no view re-triggers the other.
    quiet = page.page.evaluate("() => window.mocapqaViews.renders")
    time.sleep(1.0)
    assert page.page.evaluate("() => window.mocapqaViews.renders") == quiet
    TIMINGS["camera_drag_answer_s"] = [round(a, 3) for a in answers]
    ARTIFACTS.mkdir(exist_ok=True)
    page.page.screenshot(path=str(ARTIFACTS / "workstation-camera-shared.png"))


def test_playback_keeps_the_true_rate_and_pauses_at_once(
    live_server: str, takes: dict[str, Any], page: Page
) -> None:
    fps = takes["knees"]["result"]["summary"]["fps"]
    page.open_take(live_server, takes["knees"])
    before = page.frame()
    page.page.click("#play")
    started = time.monotonic()
    time.sleep(3.0)
    # In the page: from the key's arrival (the event's time stamp) to the end of the first frame
    # drawn after it, the time the reviewer waits to see "paused".
    page.page.evaluate(
        """() => document.addEventListener('keydown', (e) => requestAnimationFrame(() =>
          setTimeout(() => { window.pausedAfterMs = performance.now() - e.timeStamp; })),
          { capture: true, once: true })"""
    )
    clicked = time.monotonic()
    # Space on the focused play button: a real key press through the browser's input queue.
    page.page.keyboard.press("Space")
    page.page.wait_for_function(
        "() => document.getElementById('play').textContent.endsWith('play')",
        timeout=ANSWER_S * 4000,
    )
    pause_s = time.monotonic() - clicked
    page.page.wait_for_function("() => window.pausedAfterMs !== undefined")
    paused_in_page_s = page.page.evaluate("() => window.pausedAfterMs") / 1000
    played_s = time.monotonic() - started
    stopped = page.frame()
    stats = page.page.evaluate(
        "() => ({ ...window.mocapqaPlayer.stats, drawn: window.mocapqaViews.drawn,"
        " renders: window.mocapqaViews.renders })"
    )
    time.sleep(0.8)
    assert page.frame() == stopped  # paused means paused
    assert page.page.inner_text("#play").endswith("play")
    assert pause_s < ANSWER_S
    assert paused_in_page_s < ANSWER_S
    advanced = stopped - before
    # Time runs at the take's rate (frames are dropped, never slowed): at least half of it.
    assert advanced >= 0.5 * fps * 3.0, (advanced, fps)
    TIMINGS["playback"] = {
        "take": KNEES_TAKE,
        "fps": fps,
        "played_s": round(played_s, 2),
        "frames_advanced": advanced,
        "rate_vs_real_time": round(advanced / (fps * played_s), 2),
        "frames_drawn_per_s": round(stats["drawn"] / played_s, 1),
        "renders_per_s": round(stats["renders"] / played_s, 1),
        "pause_click_s": round(pause_s, 3),
        "pause_key_to_painted_s": round(paused_in_page_s, 3),
    }


def test_a_knee_twist_error_shows_in_the_oriented_bones(
    live_server: str, takes: dict[str, Any], page: Page
) -> None:
    result = takes["knees"]["result"]
    # A knee interval the run corrected: one it left for the reviewer to decide (applied: false)
    # is drawn the same in both views.
    knees = [
        f
        for f in result["findings"]
        if f["kind"] == "twist" and "Calf" in f["joint"] and f.get("applied", True)
    ]
    assert knees, [f["joint"] for f in result["findings"]]
    flagged = max(knees, key=lambda f: abs(f["value"]))
    page.open_take(live_server, takes["knees"])
    # Octahedral bones, not a stick figure.
    bones = page.page.evaluate("() => window.mocapqaViews.bones")
    assert bones == len(result["points"]["parents"]) - 1
    # A clean frame (no finding anywhere near) and the worst frame of a flagged knee interval.
    busy = set()
    for f in result["findings"]:
        busy.update(range(f["start_frame"] - 5, f["end_frame"] + 6))
    clean = next(k for k in range(20, result["summary"]["n_frames"]) if k not in busy)
    # One canvas draws both views: the two regions compared below are its two viewports.
    canvas = page.page.locator("#views canvas")
    assert canvas.count() == 1
    box = canvas.bounding_box()
    for view in ("#view-raw", "#view-corrected"):
        region = page.page.locator(view).bounding_box()
        assert box["x"] <= region["x"]
        assert region["x"] + region["width"] <= box["x"] + box["width"]
        assert box["y"] <= region["y"]
        assert region["y"] + region["height"] <= box["y"] + box["height"]
    differences = {}
    for axes in (False, True):
        if axes:
            page.page.check("#show-axes")
        for name, frame in (("clean", clean), ("flagged", flagged["start_frame"])):
            scrub(page, frame)
            raw, corrected = view_pixels(page, "#view-raw"), view_pixels(page, "#view-corrected")
            height = min(raw.shape[0], corrected.shape[0])
            width = min(raw.shape[1], corrected.shape[1])
            changed = np.abs(raw[:height, :width] - corrected[:height, :width]).sum(axis=2) > 60
            key = f"{name}{'_with_axes' if axes else ''}"
            differences[key] = int(changed.sum())
            page.page.screenshot(path=str(ARTIFACTS / f"workstation-knee-{key}-frame{frame}.png"))
    TIMINGS["knee_pixels_changed"] = {"interval": flagged, "clean_frame": clean, **differences}
    # Raw and corrected differ where the knee rolled, and nowhere at a clean frame.
    assert differences["flagged"] > 80, differences
    assert differences["flagged"] > 3 * differences["clean"], differences
    assert differences["flagged_with_axes"] > 3 * differences["clean_with_axes"], differences


def test_keyboard_only_review_from_the_take_list(
    live_server: str, takes: dict[str, Any], page: Page
) -> None:
    p = page.page
    p.goto(f"{live_server}/#/")
    p.wait_for_selector(f"#take-list tr[data-take='{takes['knees']['id']}']")
    # The take list does not load the charting library.
    assert p.evaluate(
        "() => window.Plotly === undefined && !document.querySelector('script[src*=plotly]')"
    )
    # Tab to the take's row and open it with Enter.
    for _ in range(40):
        p.keyboard.press("Tab")
        if p.evaluate("(id) => document.activeElement.dataset.take === id", takes["knees"]["id"]):
            break
    else:
        raise AssertionError("the take's row never took the focus")
    p.keyboard.press("Enter")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    page.settle()
    # No invisible toolbar button sits in the tab order.
    assert p.evaluate(
        "() => [...document.querySelectorAll('.modebar-btn')].every((b) => b.tabIndex === -1)"
    )
    # Space plays and pauses; arrows step; N/P go from finding to finding.
    p.evaluate("() => document.activeElement.blur()")
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('pause')")
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('play')")
    scrub(page, 100)
    p.keyboard.press("ArrowRight")
    assert page.frame() == 101
    p.keyboard.press("Shift+ArrowLeft")
    assert page.frame() == 91
    starts = sorted({f["start_frame"] for f in takes["knees"]["result"]["findings"]})
    p.keyboard.press("n")
    reached = next(s for s in starts if s > 91)
    assert page.frame() == reached
    # P steps back one finding: another one starting on the same frame, or the one before.
    p.keyboard.press("p")
    assert page.frame() in {reached, max(s for s in starts if s < reached)}
    # Ungrouped (space on the "group by joint" box), the "offset / outside" header sorts the whole
    # list by magnitude from the keyboard.
    p.locator("#group-joints").focus()
    p.keyboard.press("Space")
    assert not p.is_checked("#group-joints")
    header = p.locator("#findings th[data-key='value']")
    header.focus()
    p.keyboard.press("Enter")
    values = [
        float(t.split()[0]) for t in p.locator("#findings tbody td:nth-child(5)").all_inner_texts()
    ]
    assert [abs(v) for v in values] == sorted(abs(v) for v in values)
    assert any(v < 0 for v in values)
    # A focused finding opens with Enter: its frame, and the 3D views scrolled into sight.
    row = p.locator("#findings tr.finding").last
    start = int(row.get_attribute("data-start"))
    row.focus()
    p.keyboard.press("Enter")
    assert page.frame() == start
    top = p.evaluate("() => document.getElementById('view-raw').getBoundingClientRect().top")
    assert 0 <= top < p.viewport_size["height"] / 2, top
    page.settle()
    # A twist finding focuses its joint: the twist chart shows that chain only.
    twist_row = p.locator("#findings tr.finding", has_text="twist").first
    chain = twist_row.get_attribute("data-joint")
    twist_row.focus()
    p.keyboard.press("Enter")
    shown = p.evaluate(
        "() => document.getElementById('chart-twist').data"
        ".filter((t) => t.type !== 'bar' && t.visible === true).map((t) => t.legendgroup)"
    )
    assert set(shown) == {chain}
    start = page.frame()
    page.settle()
    # A decision from the keyboard (F: needs fix) is saved; the frame stays where it was.
    p.evaluate("() => document.activeElement.blur()")
    p.keyboard.press("f")
    p.wait_for_selector("#review-history li")
    assert "needs fix" in p.inner_text("#review-history")
    assert page.frame() == start
    assert f"frame={start}" in p.evaluate("() => location.hash")
    # A joint names itself on hover.
    names = takes["knees"]["result"]["points"]["names"]
    knee = names.index("CC_Base_L_Calf")
    p.evaluate("() => document.getElementById('views').scrollIntoView()")
    page.settle()
    x, y = p.evaluate("(j) => window.mocapqaViews.screenOf('raw', j)", knee)
    p.mouse.move(x, y)
    p.wait_for_selector(".joint-tooltip:not([hidden])")
    named = p.inner_text(".joint-tooltip")
    assert named in names
    # A click on it selects it: named in the player bar and in the URL.
    p.mouse.click(x, y)
    assert p.inner_text("#joint-label") == f"selected: {named}"
    assert f"joint={named}" in p.evaluate("() => location.hash")
    p.screenshot(path=str(ARTIFACTS / "workstation-keyboard-review.png"), full_page=True)


def test_linked_zoom_resets_together(live_server: str, takes: dict[str, Any], page: Page) -> None:
    page.open_take(live_server, takes["knees"])
    p = page.page
    p.evaluate(
        "() => Plotly.relayout('chart-twist', {'xaxis.range[0]': 100, 'xaxis.range[1]': 200})"
    )
    p.wait_for_function(
        "() => document.getElementById('chart-limits').layout.xaxis.range[1] === 200"
    )
    # Double-click the twist chart's plot area: both charts reset.
    p.locator("#chart-twist .nsewdrag").first.dblclick()
    p.wait_for_function(
        "() => ['chart-twist', 'chart-limits'].every((id) =>"
        " document.getElementById(id)._fullLayout.xaxis.range[1] > 400)",
        timeout=10_000,
    )
    # The two charts' plot areas start and end at the same x: their time cursors line up.
    edges = p.evaluate(
        "() => ['chart-twist', 'chart-limits'].map((id) => { const a ="
        " document.getElementById(id)._fullLayout.xaxis; return [a._offset, a._length]; })"
    )
    assert edges[0] == edges[1]


def test_narrow_window_and_a_keypoint_take(
    live_server: str, takes: dict[str, Any], chromium: Any
) -> None:
    narrow = Page(chromium, width=900, height=900)
    p = narrow.page
    p.goto(f"{live_server}/#/")
    p.wait_for_selector("#take-list tbody tr")
    assert p.evaluate("() => document.documentElement.scrollWidth <= window.innerWidth")
    p.screenshot(path=str(ARTIFACTS / "workstation-list-900px.png"), full_page=True)
    narrow.open_take(live_server, takes["knees"])
    assert p.evaluate("() => document.documentElement.scrollWidth <= window.innerWidth")
    # Play is on screen without scrolling, and the two views sit side by side above it.
    play = p.locator("#play").bounding_box()
    views = [p.locator(v).bounding_box() for v in ("#view-raw", "#view-corrected")]
    assert play["y"] + play["height"] <= 900
    assert views[0]["y"] == views[1]["y"]
    assert views[0]["x"] < views[1]["x"]
    assert all(v["y"] + v["height"] <= play["y"] for v in views)
    # The scrubber spans the player bar, as the time bar under it does (not squeezed beside
    # the read-outs, nor pushing them onto a line of their own).
    player, scrubber = p.locator("#player").bounding_box(), p.locator("#scrubber").bounding_box()
    timebar = p.locator("#timebar").bounding_box()
    assert scrubber["width"] >= 0.95 * timebar["width"]
    assert player["x"] <= scrubber["x"]
    assert scrubber["x"] + scrubber["width"] <= player["x"] + player["width"]
    read_outs = [p.locator(sel).bounding_box() for sel in ("#play", "#frame-label", "#joint-label")]
    middles = [b["y"] + b["height"] / 2 for b in read_outs]
    assert max(middles) - min(middles) < 2  # on one line
    p.screenshot(path=str(ARTIFACTS / "workstation-take-900px.png"))
    # A TRC take (marker data): the re-run form offers the marker checks and the filter; the
    # run picker names what ran.
    narrow.open_take(live_server, takes["trc"])
    offered = p.evaluate(
        "() => [...document.querySelectorAll('#rerun-panel input[name=check]')].map((c) => c.value)"
    )
    assert offered == ["markers", "feet", "filter"]
    # Pose2Sim's markers are joined by the bones of their layout, not drawn as loose dots.
    assert p.evaluate("() => window.mocapqaViews.lines") >= 20
    # Every keypoint (the head's too) is drawn inside both views, clear of their edges.
    margins = p.evaluate(
        "() => ['raw', 'corrected'].flatMap((name) => { const v = window.mocapqaViews;"
        " const d = document.getElementById(name === 'raw' ? 'view-raw' : 'view-corrected');"
        " const r = d.getBoundingClientRect(); const out = [];"
        " for (let j = 0; j < v.points; j++) { const [x, y] = v.screenOf(name, j);"
        " if (Number.isFinite(y))"
        " out.push(Math.min(x - r.left, r.right - x, y - r.top, r.bottom - y)); }"
        " return out; })"
    )
    assert len(margins) >= 20
    assert min(margins) >= 5, margins
    assert "twist" not in p.inner_text("#run-pick")
    p.screenshot(path=str(ARTIFACTS / "workstation-keypoints.png"), full_page=True)
    narrow.close()


def chromium_cpu_s() -> float:
    """CPU seconds (user + system) so far of the Chromium processes this session started."""
    import psutil  # type: ignore[import-untyped]

    total = 0.0
    for process in psutil.Process().children(recursive=True):
        try:
            if "chrom" in process.name():
                times = process.cpu_times()
                total += times.user + times.system
        except psutil.NoSuchProcess:
            continue
    return total


def check_decimated_charts(page: Any) -> dict[str, list[Any]]:
    """The big take's charts drawn from at most four points per pixel column look as the full
    data would: the same y-ranges and bands as the full figure plotted in a box of the same size,
    and a zoom into 100 frames draws every sample of the full series there. Returns the points
    each chart was handed against its full data's."""
    out = page.evaluate(
        r"""async () => {
          const same = [];
          const drawn = {};
          for (const chart of window.mocapqaCharts.charts) {
            const div = chart.div;
            const full = document.createElement('div');
            full.style.width = `${div.clientWidth}px`; full.style.height = `${div.clientHeight}px`;
            div.parentElement.append(full);
            const { data, layout } = chart.figure;
            await Plotly.newPlot(full, data, layout, { displaylogo: false });
            const ranges = (d) => Object.keys(d._fullLayout).filter((k) => /^[xy]axis\d*$/.test(k))
              .map((k) => [k, d._fullLayout[k].range.map((v) => Math.round(v * 1000) / 1000)]);
            const bands = (d) => d.data.filter((t) => t.type === 'bar')
              .map((t) => [t.x, t.width, t.base]);
            same.push([div.id, JSON.stringify(ranges(div)), JSON.stringify(ranges(full)),
              JSON.stringify(bands(div)) === JSON.stringify(bands(full))]);
            const points = (d) => d.data.reduce((n, t) => n + (t.x ? t.x.length : 0), 0);
            // At most four samples per pixel column of a line, one cell per column of a heat map.
            const w = div._fullLayout._size.w;
            const bounded = div.data.every((t) => t.type === 'heatmap' ? t.z[0].length <= w
              : t.type !== 'scatter' || t.stackgroup || t.x.length <= 4 * w);
            drawn[div.id] = [points(div), points(full), Math.round(w), bounded];
            Plotly.purge(full); full.remove();
          }
          // Zoom into 100 frames: the shown lines hold every sample of the range.
          const chart0 = (div) => window.mocapqaCharts.charts.find((c) => c.div === div);
          await Plotly.relayout('chart-twist', { 'xaxis.range': [5000, 5100] });
          const twist = document.getElementById('chart-twist');
          const k = twist.data.findIndex((t) => t.type === 'scatter' && t.visible === true);
          const within = (x) => x.filter((f) => f >= 5000 && f <= 5100);
          const inside = [within(twist.data[k].x), within(chart0(twist).figure.data[k].x)];
          await Plotly.relayout('chart-twist', { 'xaxis.autorange': true });
          return { same, drawn, inside }; }"""
    )
    for chart_id, drawn, full, bands in out["same"]:
        assert drawn == full, (chart_id, drawn, full)
        assert bands, chart_id
    for chart_id, (points, all_points, width, bounded) in out["drawn"].items():
        assert bounded, (chart_id, width)
        assert points <= all_points, (chart_id, points, all_points)
    assert out["drawn"]["chart-limits"][0] < out["drawn"]["chart-limits"][1]
    shown, full = out["inside"]
    assert shown == full, (shown, full)
    assert len(full) > 10, full
    return out["drawn"]


def tiled_walk(corpus_dir: Path, folder: Path, n_frames: int = 10_000) -> Path:
    """The CMU walk (31 joints) repeated to ``n_frames`` frames, as the load test does."""
    from dataclasses import replace

    from mocapqa.io.bvh import read_bvh
    from mocapqa.io.bvh_write import format_bvh

    walk = read_bvh(corpus_dir / "bvh/cmu/cmu_12_01_walk.bvh")
    reps = int(np.ceil(n_frames / (walk.n_frames - 1)))
    quats = np.concatenate([walk.quats[1:]] * reps)[:n_frames]
    translations = np.concatenate([walk.translations[1:]] * reps)[:n_frames]
    big = replace(walk, quats=quats, translations=translations, euler_hint_deg=None)
    path = folder / "cmu_walk_10000_frames.bvh"
    path.write_text(format_bvh(big))
    return path


def test_timings_overlay_and_upload_progress(
    live_server: str, takes: dict[str, Any], chromium: Any, corpus_dir: Path, tmp_path: Path
) -> None:
    # Upload progress counts bytes: the bar's maximum is the file's size.
    page = Page(chromium)
    p = page.page
    path = tiled_walk(corpus_dir, tmp_path)
    p.goto(f"{live_server}/#/upload")
    p.set_input_files("#file-input", str(path))
    p.wait_for_selector("#open-take", timeout=300_000)
    size = path.stat().st_size
    assert p.get_attribute("#upload-progress", "max") == str(size)
    assert p.evaluate("() => document.getElementById('upload-progress').value") == size
    href = p.get_attribute("#open-take", "href")
    page.close()

    # A fresh page on the 10,000-frame take: skeletons after the first paint.
    fresh = Page(chromium)
    # Every main-thread task over 50 ms from the page's start: input waits behind them.
    fresh.page.add_init_script(
        "window.longTasks = []; new PerformanceObserver((list) => { for (const e of"
        " list.getEntries()) window.longTasks.push([e.startTime, e.duration]); })"
        ".observe({ type: 'longtask', buffered: true });"
    )
    fresh.page.goto(f"{live_server}/{href}")
    fresh.page.wait_for_selector("main[data-ready='1']", timeout=60_000)
    fresh.settle()
    long_tasks = fresh.page.evaluate("() => window.longTasks")
    marks = fresh.page.evaluate(
        "() => Object.fromEntries(['first-contentful-paint', 'take-fetched', 'result-fetched',"
        " 'frames-fetched', 'views-start', 'skeletons-drawn'].map((n) =>"
        " [n, performance.getEntriesByName(n)[0].startTime]))"
    )
    marks["fcp"], marks["skeletons"] = marks["first-contentful-paint"], marks["skeletons-drawn"]
    plot_ms = fresh.page.evaluate(
        "() => performance.getEntriesByType('measure').filter((m) => m.name.startsWith('plot '))"
        ".map((m) => [m.name.slice(5), Math.round(m.startTime) / 1000, Math.round(m.duration)])"
    )
    in_use = fresh.page.evaluate("() => performance.now()")
    # Scrubbing, measured two ways. "paced": 60 scrubber moves, each waited for two animation
    # frames (drawn, then painted), so at most half the display's rate (30/s at 60 Hz).
    # "per frame": a move in every animation frame, as a drag on the scrubber delivers them, for
    # 120 frames: the updates the views drew per second. The idle page's animation frames per
    # second are the display's rate, the ceiling of the second figure.
    scrub = fresh.page.evaluate(
        """async () => {
          const s = document.getElementById('scrubber');
          const views = window.mocapqaViews;
          const frame = () => new Promise((r) => requestAnimationFrame(r));
          await frame();
          let t0 = performance.now();
          for (let k = 0; k < 60; k++) {
            s.value = 1000 + 37 * k; s.dispatchEvent(new Event('input'));
            await frame(); await frame();
          }
          const paced = (performance.now() - t0) / 1000;
          t0 = performance.now();
          for (let k = 0; k < 30; k++) await frame();
          const idle = (performance.now() - t0) / 1000;
          return { paced, idle, canvases: document.querySelectorAll('#views canvas').length }; }"""
    )
    # The per-frame moves, with the CPU time all of Chromium's processes spent on them.
    cpu_before = chromium_cpu_s()
    scrub |= fresh.page.evaluate(
        """async () => {
          const s = document.getElementById('scrubber');
          const views = window.mocapqaViews;
          const frame = () => new Promise((r) => requestAnimationFrame(r));
          await frame();
          const renders = views.renders, t0 = performance.now();
          for (let k = 0; k < 120; k++) {
            s.value = 3000 + 37 * k; s.dispatchEvent(new Event('input'));
            await frame();
          }
          return { perFrame: (performance.now() - t0) / 1000, drawn: views.renders - renders }; }"""
    )
    cpu_s = chromium_cpu_s() - cpu_before
    # Playback of the 120 fps take for 3 s, read in the page: frames are dropped, time is kept.
    from mocapqa.io.bvh import read_bvh

    fps = read_bvh(path).fps
    played = fresh.page.evaluate(
        """async () => {
          const frameNow = () =>
            Number(document.getElementById('frame-label').textContent.split(' ')[1]);
          const views = window.mocapqaViews;
          const first = frameNow(), drawn = views.drawn, t0 = performance.now();
          document.getElementById('play').click();
          await new Promise((r) => setTimeout(r, 3000));
          const last = frameNow(), seconds = (performance.now() - t0) / 1000;
          document.getElementById('play').click();
          return { frames: last - first, seconds, drawn: views.drawn - drawn }; }"""
    )
    drag_camera(fresh, "#view-raw")
    fresh.settle()
    used_tasks = [
        [round(start / 1000, 3), round(ms)]
        for start, ms in fresh.page.evaluate("() => window.longTasks")
        if start >= in_use
    ]
    charts = check_decimated_charts(fresh.page)
    fresh.close()
    TIMINGS["big_take"] = {
        "frames": 10_000,
        "joints": 31,
        "first_contentful_paint_s": round(marks["fcp"] / 1000, 3),
        "skeletons_after_first_paint_s": round((marks["skeletons"] - marks["fcp"]) / 1000, 3),
        "scrub_frames_per_s": round(60 / scrub["paced"], 1),
        "scrub_updates_per_s": round(scrub["drawn"] / scrub["perFrame"], 1),
        "animation_frames_per_s": round(30 / scrub["idle"], 1),
        "scrub_cpu_ms_per_update": round(1000 * cpu_s / scrub["drawn"], 1),
        "marks_s": {k: round(v / 1000, 3) for k, v in marks.items()},
        "chart_points_drawn": charts,
        # Each chart's plotting (from the chart's box to Plotly's promise): [chart, start s, ms].
        "chart_plot_ms": plot_ms,
        # Tasks over 100 ms once the skeletons were drawn, until the page was ready: [start, ms].
        "tasks_over_100ms_after_skeletons": [
            [round(start / 1000, 3), round(ms)]
            for start, ms in long_tasks
            if ms > 100 and start + ms > marks["skeletons"]
        ],
        "playback": {
            "fps": fps,
            "rate_vs_real_time": round(played["frames"] / (fps * played["seconds"]), 2),
            "frames_drawn_per_s": round(played["drawn"] / played["seconds"], 1),
        },
        # Every task over 50 ms while the ready page was used (scrubbing, playback of the
        # 120 fps take, a camera drag): [start s, ms].
        "tasks_over_50ms_while_used": used_tasks,
    }
    assert fps == pytest.approx(120.0, rel=1e-3)
    # Time runs at the take's rate, dropping frames (at most 60 of its 120 per second can be
    # drawn at the display's rate): at least half of it, as in the playback test.
    assert played["frames"] >= 0.5 * fps * played["seconds"], played
    assert marks["skeletons"] > marks["fcp"]
    # One canvas draws both views; every move of the scrubber was drawn.
    assert scrub["canvases"] == 1
    assert scrub["drawn"] >= 120, scrub

    # Overlay: one view, corrected solid and raw as a ghost, at a flagged knee frame.
    overlay = Page(chromium)
    result = takes["knees"]["result"]
    knee = max(
        (f for f in result["findings"] if f["kind"] == "twist" and "Calf" in f["joint"]),
        key=lambda f: abs(f["value"]),
    )
    overlay.open_take(live_server, takes["knees"], frame=knee["start_frame"])
    assert overlay.frame() == knee["start_frame"]  # the URL carries the frame
    alone = view_pixels(overlay, "#view-corrected")
    overlay.page.check("#overlay")
    overlay.settle()
    assert overlay.page.is_hidden("#panel-raw")
    ghosted = view_pixels(overlay, "#view-corrected")
    overlay.page.screenshot(path=str(ARTIFACTS / "workstation-overlay.png"))
    if alone.shape == ghosted.shape:
        assert (np.abs(alone - ghosted).sum(axis=2) > 60).sum() > 100
    overlay.page.check("#show-axes")
    overlay.settle()
    overlay.page.screenshot(path=str(ARTIFACTS / "workstation-overlay-axes.png"))
    overlay.close()


def test_compare_matches_findings_and_diffs_options(
    live_server: str, takes: dict[str, Any], page: Page
) -> None:
    knees = takes["knees"]
    other = run_again(live_server, knees["id"], {"checks": ["twist"], "twist_method": "paper"})
    p = page.page
    p.goto(f"{live_server}/#/compare?a={knees['run']}&b={other}")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    options = p.inner_text("#compare-options")
    assert "twist_method" in options
    assert "paper" in options
    assert "checks" in options
    matches = set(
        p.locator("#compare-findings tbody tr").evaluate_all("rs => rs.map(r => r.dataset.match)")
    )
    # B ran no limits check: A's limits findings are only in A.
    assert "only in A" in matches
    # The counts by kind add up to the findings, spins included.
    table = p.inner_text("#compare-table")
    spins = sum(f["kind"] == "spin" for f in knees["result"]["findings"])
    assert spins > 0
    assert f"limb spins (reported, not corrected)\t{spins}\t{spins}" in table
    # How many intervals each run applied, and by which choice.
    applied = sum(f["kind"] == "twist" and f["applied"] for f in knees["result"]["findings"])
    assert f"twist intervals applied\t{applied} (confident)" in table
    assert p.evaluate("() => document.getElementById('compare-twist').data.length") == 4
    # Both runs side by side in 3D, one camera: a drag in A's view turns B's too.
    assert p.locator("#compare-3d canvas").count() == 1  # one canvas draws both runs
    views = p.evaluate("() => window.mocapqaCompareViews.points")
    assert views == len(knees["result"]["points"]["names"])
    before = p.evaluate("() => window.mocapqaCompareViews.orbit.azimuth")
    p.locator("#compare-view-a").scroll_into_view_if_needed()
    box = p.locator("#compare-view-a").bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    p.mouse.move(x, y)
    p.mouse.down()
    for step in range(1, 8):
        p.mouse.move(x + 10 * step, y)
    p.mouse.up()
    assert p.evaluate("() => window.mocapqaCompareViews.orbit.azimuth") != pytest.approx(before)
    # The scrubber moves both; an offset moves B only (same fps: B = A + offset). The row's last
    # child is the canvas, hence "of-type": the columns are its only divs.
    p.locator("#compare-scrubber").fill("200")
    assert "frame 200" in p.inner_text("#compare-3d .col:first-of-type .view-title")
    assert "frame 200" in p.inner_text("#compare-3d .col:last-of-type .view-title")
    p.fill("#compare-offset", "-10")
    assert "frame 190" in p.inner_text("#compare-3d .col:last-of-type .view-title")
    p.locator("#compare-3d").scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "workstation-compare-3d.png"))
    # At 900 px the two views stay side by side, with no sideways scroll.
    p.set_viewport_size({"width": 900, "height": 900})
    p.wait_for_function("() => document.documentElement.scrollWidth <= window.innerWidth")
    a_box, b_box = (p.locator(v).bounding_box() for v in ("#compare-view-a", "#compare-view-b"))
    assert a_box["y"] == b_box["y"]
    assert a_box["x"] < b_box["x"]
    p.evaluate("() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))")
    p.locator("#compare-3d").scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "workstation-compare-3d-900px.png"))
    p.screenshot(path=str(ARTIFACTS / "workstation-compare.png"), full_page=True)
