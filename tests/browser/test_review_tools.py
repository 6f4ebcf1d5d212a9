"""The reviewer's tools in the take view, driven as a reviewer drives them, on 005_05.

The findings list grouped by joint with its filters and N/P across the groups; the loop range
(I/O keys, a drag on the time bar, L) and "loop this finding"; the close-in and follow cameras.
Screenshots go to ``tests/artifacts/`` (gitignored): ``review-findings-grouped.png``,
``review-findings-filtered.png``, ``review-loop.png``, ``review-close-in.png``,
``review-follow.png``, and the same at 900 px (``…-900px.png``).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.browser.test_workstation import ARTIFACTS, KNEES_TAKE, TRC_TAKE, Page, scrub, upload

pytestmark = pytest.mark.browser


@pytest.fixture(scope="module")
def knees(live_server: str, corpus_dir: Path) -> dict[str, Any]:
    return upload(live_server, corpus_dir / KNEES_TAKE)


@pytest.fixture(params=[1280, 900], ids=["1280px", "900px"])
def page(chromium: Any, request: pytest.FixtureRequest) -> Iterator[Page]:
    opened = Page(chromium, width=request.param, height=900)
    yield opened
    assert opened.page.evaluate("() => document.documentElement.scrollWidth <= window.innerWidth")
    opened.close()


def shot(page: Page, name: str) -> None:
    width = page.page.viewport_size["width"]
    ARTIFACTS.mkdir(exist_ok=True)
    suffix = "" if width >= 1000 else f"-{width}px"
    page.page.screenshot(path=str(ARTIFACTS / f"review-{name}{suffix}.png"))


def rows(page: Page) -> list[dict[str, Any]]:
    """The finding rows shown, as the page lists them."""
    return page.page.locator("#findings tr.finding").evaluate_all(
        "rs => rs.map((r) => ({ kind: r.cells[0].innerText, joint: r.dataset.joint,"
        " start: Number(r.dataset.start), value: r.cells[4].innerText,"
        " current: r.classList.contains('current') }))"
    )


def test_findings_grouped_by_joint_filtered_and_walked(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    findings = knees["result"]["findings"]
    joints = {f["joint"] for f in findings}
    page.open_take(live_server, knees)
    # One collapsible group per joint, its count and worst value in the heading.
    heads = p.locator("#findings tr.group-head")
    head_joints = heads.evaluate_all("hs => hs.map((h) => h.dataset.joint)")
    assert sorted(head_joints) == sorted(joints)
    for k, joint in enumerate(head_joints):
        text = heads.nth(k).inner_text()
        count = sum(f["joint"] == joint for f in findings)
        assert f" · {count} finding{'' if count == 1 else 's'} · " in text, text
        values = [
            abs(f["value"]) for f in findings if f["joint"] == joint and f["value"] is not None
        ]
        if values:
            assert f" · worst {max(values):.1f} " in text, text
        else:
            assert "worst" not in text, text
    assert len(rows(page)) == len(findings)
    # Each limits finding shows its anatomical read-out under the joint ("… over-inverted 136°"),
    # each limb spin its sentence ("right arm spun 24° about its axis …"), each twist interval
    # what the default does with it and why ("the default applies it: calibrated probability
    # 0.82 …").
    readouts = [f["readout"] for f in findings if f.get("readout")]
    assert {f["kind"] for f in findings if f.get("readout")} >= {"limits", "twist"}
    assert any(r.startswith("the default ") for r in readouts)
    shown = p.locator("#findings tr.finding .readout").all_inner_texts()
    assert sorted(shown) == sorted(readouts)
    p.locator("#findings-panel").scroll_into_view_if_needed()
    shot(page, "findings-grouped")

    # A click folds a group; Enter on its focused heading opens it again.
    busiest = max(joints, key=lambda j: sum(f["joint"] == j for f in findings))
    head = p.locator(f"#findings tr.group-head[data-joint='{busiest}']")
    head.click()
    assert head.get_attribute("aria-expanded") == "false"
    assert not any(r["joint"] == busiest for r in rows(page))
    p.locator(f"#findings tr.group-head[data-joint='{busiest}']").focus()
    p.keyboard.press("Enter")
    assert sum(r["joint"] == busiest for r in rows(page)) == sum(
        f["joint"] == busiest for f in findings
    )

    # Filters: kind, joint, smallest magnitude, words.
    kinds = {f["kind"] for f in findings}
    p.uncheck("#filter-kind-limits")
    assert {r["kind"] for r in rows(page)} == kinds - {"limits"}
    for kind in kinds - {"limits", "twist"}:
        p.uncheck(f"#filter-kind-{kind}")
    assert {r["kind"] for r in rows(page)} == {"twist"}
    assert "shown" in p.inner_text("#findings-panel h2")
    for kind in kinds - {"twist"}:
        p.check(f"#filter-kind-{kind}")
    p.select_option("#filter-joint", busiest)
    assert {r["joint"] for r in rows(page)} == {busiest}
    p.select_option("#filter-joint", "")
    p.fill("#filter-min", "20")
    shown = rows(page)
    assert shown
    assert all(abs(float(r["value"].split()[0])) >= 20 for r in shown)
    assert len(shown) == sum(f["value"] is not None and abs(f["value"]) >= 20 for f in findings)
    p.fill("#filter-min", "")
    p.fill("#filter-text", "no such joint")
    assert p.inner_text("#findings-none") == "No finding matches the filters."
    p.fill("#filter-text", "calf")
    assert p.locator("#findings-none").count() == 0
    assert rows(page)
    assert all("calf" in r["joint"].lower() for r in rows(page))
    shot(page, "findings-filtered")
    p.fill("#filter-text", "")

    # N walks every finding kept, across groups, from the first frame: a folded group opens.
    p.locator(f"#findings tr.group-head[data-joint='{busiest}']").click()
    scrub(page, 0)
    p.evaluate("() => document.activeElement.blur()")
    # One stop per finding, in time order: two findings starting on one frame are two stops.
    later = sorted(
        (f["start_frame"], f["joint"], f["kind"]) for f in findings if f["start_frame"] > 0
    )
    visited = []
    for _ in later:
        p.keyboard.press("n")
        current = [r for r in rows(page) if r["current"]]
        assert len(current) == 1
        assert page.frame() == current[0]["start"]
        visited.append((current[0]["start"], current[0]["joint"], current[0]["kind"]))
    assert sorted(visited) == later
    assert [v[0] for v in visited] == sorted(v[0] for v in visited)
    p.keyboard.press("n")
    assert visited[-1][0] == page.frame()  # the last finding: N stays
    p.keyboard.press("p")
    back = [r for r in rows(page) if r["current"]]
    assert (back[0]["start"], back[0]["joint"], back[0]["kind"]) == visited[-2]
    # With only the twist kind kept, N and P stop at twist findings only, and the time bar
    # marks only those.
    marks = "() => document.querySelectorAll('#timebar .tb-mark').length"
    assert p.evaluate(marks) == len(findings)
    for kind in kinds - {"twist"}:
        p.uncheck(f"#filter-kind-{kind}")
    assert p.evaluate(marks) == sum(f["kind"] == "twist" for f in findings)
    p.evaluate("() => document.activeElement.blur()")
    scrub(page, 0)
    twist_starts = sorted({f["start_frame"] for f in findings if f["kind"] == "twist"})
    p.keyboard.press("n")
    assert page.frame() == twist_starts[0]
    p.keyboard.press("n")
    assert page.frame() == twist_starts[1]

    # A click on a finding jumps the player and the time bar's cursor to its start.
    row = p.locator("#findings tr.finding").last
    start = int(row.get_attribute("data-start"))
    row.click()
    assert page.frame() == start
    cursor = p.evaluate(
        "() => { const b = document.getElementById('timebar').getBoundingClientRect();"
        " const c = document.querySelector('.tb-cursor').getBoundingClientRect();"
        " return (c.left - b.left) / b.width; }"
    )
    assert cursor == pytest.approx((start + 0.5) / knees["result"]["summary"]["n_frames"], abs=0.01)

    # The filters travel in the link: whoever opens it sees the same list.
    p.fill("#filter-min", "20")
    link = p.evaluate("() => location.hash")
    assert "kinds=twist" in link
    assert "atleast=20" in link
    kept = [(r["start"], r["joint"]) for r in rows(page)]
    assert kept
    p.goto("about:blank")
    p.goto(f"{live_server}/{link}")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert not p.is_checked("#filter-kind-limits")
    assert p.input_value("#filter-min") == "20"
    assert [(r["start"], r["joint"]) for r in rows(page)] == kept


def loop_range(page: Page) -> list[int] | None:
    value: list[int] | None = page.page.evaluate("() => window.mocapqaPlayer.loop")
    return value


def frames_while_playing(page: Page, seconds: float) -> list[int]:
    seen = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        seen.append(page.frame())
        time.sleep(0.05)
    return seen


def test_loop_a_range_and_loop_the_finding(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    n_frames = knees["result"]["summary"]["n_frames"]
    page.open_take(live_server, knees)
    # I and O at two frames, then L: playback stays inside.
    scrub(page, 100)
    p.evaluate("() => document.activeElement.blur()")
    p.keyboard.press("i")
    scrub(page, 130)
    p.evaluate("() => document.activeElement.blur()")
    p.keyboard.press("o")
    assert "in 100 · out 130" in p.inner_text("#loop-label")
    assert "loop=100-130" in p.evaluate("() => location.hash")  # a link carries the range
    assert loop_range(page) is None  # set, not looping yet
    p.keyboard.press("l")
    assert p.get_attribute("#loop", "aria-pressed") == "true"
    assert loop_range(page) == [100, 130]
    p.keyboard.press("Space")
    seen = frames_while_playing(page, 2.5)
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('play')")
    assert all(100 <= f <= 130 for f in seen), seen
    assert len(set(seen)) > 3  # it played
    # 31 frames at 60 fps loop in about half a second: 2.5 s went round (frames went back).
    assert any(b < a for a, b in itertools.pairwise(seen)), seen
    p.locator("#player").scroll_into_view_if_needed()
    shot(page, "loop")

    # A drag along the time bar sets a new range; a drag of its in handle moves the in point.
    bar = p.locator("#timebar").bounding_box()
    y = bar["y"] + bar["height"] / 2

    def x_of(frame: int) -> float:
        return float(bar["x"] + bar["width"] * frame / (n_frames - 1))

    p.mouse.move(x_of(200), y)
    p.mouse.down()
    for k in range(1, 11):
        p.mouse.move(x_of(200) + k * (x_of(300) - x_of(200)) / 10, y)
    p.mouse.up()
    dragged = loop_range(page)
    assert dragged is not None
    assert abs(dragged[0] - 200) <= 2, dragged
    assert abs(dragged[1] - 300) <= 2, dragged
    handle = p.locator(".tb-in").bounding_box()
    p.mouse.move(handle["x"] + handle["width"] / 2, y)
    p.mouse.down()
    for k in range(1, 6):
        p.mouse.move(handle["x"] + handle["width"] / 2 - k * (x_of(50) - x_of(0)) / 5, y)
    p.mouse.up()
    moved = loop_range(page)
    assert moved is not None
    assert abs(moved[0] - 150) <= 3, moved
    assert moved[1] == dragged[1], moved
    # A click on the bar (no drag) goes to its frame and keeps the range.
    p.mouse.click(x_of(400), y)
    assert abs(page.frame() - 400) <= 2
    assert loop_range(page) == moved
    # L again stops looping; "clear in/out" forgets the range.
    p.keyboard.press("l")
    assert loop_range(page) is None
    p.click("#loop-clear")
    assert "none" in p.inner_text("#loop-label")
    band = p.locator("#loop-band")
    assert band.count() == 1  # hidden, not gone: a later range shows it again
    assert band.is_hidden()

    # Loop this finding: open a twist finding, shift+L plays its frames with a margin.
    twist = next(f for f in knees["result"]["findings"] if f["kind"] == "twist")
    p.locator(
        f"#findings tr.finding[data-start='{twist['start_frame']}'][data-joint='{twist['joint']}']"
        "[data-kind='twist']"
    ).click()
    p.evaluate("() => document.activeElement.blur()")
    p.keyboard.press("Shift+L")
    margin = round(0.5 * knees["result"]["summary"]["fps"])
    expected = [
        max(0, twist["start_frame"] - margin),
        min(n_frames - 1, twist["end_frame"] + margin),
    ]
    assert loop_range(page) == expected
    assert p.inner_text("#play").endswith("pause")
    seen = frames_while_playing(page, 1.5)
    p.click("#play")
    assert all(expected[0] <= f <= expected[1] for f in seen), (seen, expected)
    assert p.locator("#findings tr.finding.current").get_attribute("data-joint") == twist["joint"]

    # A link with a range opens with it set (not looping).
    p.goto(f"{live_server}/#/take/{knees['id']}?run={knees['run']}&frame=5&loop=20-40")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert "in 20 · out 40" in p.inner_text("#loop-label")
    assert loop_range(page) is None


def test_close_in_on_a_joint_and_follow_the_root(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    result = knees["result"]
    names, parents = result["points"]["names"], result["points"]["parents"]
    knee = max(
        (f for f in result["findings"] if f["kind"] == "twist" and "Calf" in f["joint"]),
        key=lambda f: abs(f["value"]),
    )
    page.open_take(live_server, knees)
    p.locator(
        f"#findings tr.finding[data-start='{knee['start_frame']}'][data-joint='{knee['joint']}']"
        f"[data-kind='{knee['kind']}']"
    ).click()
    page.settle()
    before = p.evaluate("() => window.mocapqaViews.orbit")

    def off_centre(index: int) -> float:
        """Distance of a point from the corrected view's centre, as a share of its width."""
        x, y = p.evaluate("(j) => window.mocapqaViews.screenOf('corrected', j)", index)
        box = p.locator("#view-corrected").bounding_box()
        cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        return float(((x - cx) ** 2 + (y - cy) ** 2) ** 0.5 / box["width"])

    joint = names.index(knee["joint"])
    p.click("#camera-close")
    page.settle()
    close = p.evaluate("() => window.mocapqaViews.orbit")
    assert p.get_attribute("#camera-close", "aria-pressed") == "true"
    assert close["distance"] < 0.5 * before["distance"]
    assert off_centre(joint) < 0.02
    # The camera stays on the joint while the frame changes.
    p.evaluate("() => document.activeElement.blur()")
    p.keyboard.press("Shift+ArrowRight")
    page.settle()
    assert off_centre(joint) < 0.02
    shot(page, "close-in")
    # C leaves close-in.
    p.keyboard.press("c")
    page.settle()
    assert p.get_attribute("#camera-close", "aria-pressed") == "false"
    assert p.evaluate("() => window.mocapqaViews.orbit.distance") == pytest.approx(
        before["distance"]
    )

    # Follow: the root stays in the centre while playing.
    root = parents.index(-1)
    p.click("#camera-follow")
    assert p.get_attribute("#camera-follow", "aria-pressed") == "true"
    p.click("#play")
    seen = []
    for _ in range(5):
        time.sleep(0.3)
        seen.append((page.frame(), off_centre(root)))
    p.click("#play")
    page.settle()
    assert len({frame for frame, _ in seen}) > 1  # it played
    assert all(share < 0.02 for _, share in seen), seen
    assert p.evaluate("() => window.mocapqaViews.focus") == "root"
    shot(page, "follow")


def test_options_form_grouped_with_units_presets_and_checks(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees)
    panel = p.locator("#rerun-panel")
    panel.scroll_into_view_if_needed()
    groups = panel.locator("fieldset.option-group").evaluate_all(
        "fs => fs.map(f => f.dataset.group)"
    )
    # A BVH take also has its rig roles (the mapping), folded when every role was found.
    assert groups == ["twist", "limits", "feet", "filter", "advanced", "roles"]
    assert p.locator("#options-roles").get_attribute("open") is None
    # Every numeric field carries its unit: the advanced one, and the filter's parameters.
    p.click("#options-advanced summary")
    assert "samples" in p.inner_text("#options-advanced")
    # A preset fills the form from the server's presets (pipeline/options.py).
    p.select_option("#run-preset", "twist only")
    ticked = panel.locator("input[name=check]").evaluate_all(
        "bs => bs.filter(b => b.checked).map(b => b.value)"
    )
    assert ticked == ["twist"]
    p.select_option("#run-preset", "full check, no twist interval applied (decide each)")
    assert p.input_value("#option-twist_apply") == "none"
    # The filter's parameters come from the registry, each with its unit.
    p.select_option("#filter-method", "butterworth")
    cutoff = panel.locator("[data-param='cutoff_hz']")
    assert cutoff.locator("xpath=..").locator(".unit").inner_text() == "Hz"
    # A typo is refused in the page, naming the field; nothing is sent.
    runs_before = len(
        httpx.get(f"{live_server}/api/v1/takes/{knees['id']}", timeout=30).json()["runs"]
    )
    cutoff.fill("fast")
    p.fill("#option-max_points", "5")
    p.click("#rerun")
    message = p.inner_text("#rerun-message")
    assert "cutoff_hz: expected a number" in message
    assert "max_points: expected at least 10" in message
    assert cutoff.get_attribute("aria-invalid") == "true"
    max_points = p.locator("#option-max_points")
    assert max_points.get_attribute("aria-invalid") == "true"
    # The keyboard is taken to the first field at fault.
    assert p.evaluate("() => document.activeElement.dataset.param") == "cutoff_hz"
    shot(page, "options-form")
    time.sleep(0.5)
    runs_after = len(
        httpx.get(f"{live_server}/api/v1/takes/{knees['id']}", timeout=30).json()["runs"]
    )
    assert runs_after == runs_before
    # Fixed, the run starts with exactly those options; the first change clears the refusal.
    p.select_option("#run-preset", "twist only")
    assert p.inner_text("#rerun-message") == ""
    # The preset has no filter, so the cut-off went with it; the field that stays is unmarked.
    assert cutoff.count() == 0
    assert max_points.count() == 1
    assert max_points.get_attribute("aria-invalid") is None
    p.select_option("#filter-method", "butterworth")
    assert cutoff.count() == 1
    assert cutoff.get_attribute("aria-invalid") is None
    cutoff.fill("4")
    p.fill("#option-max_points", "300")
    p.click("#rerun")
    p.wait_for_function("(n) => !location.hash.includes(n)", arg=knees["run"])
    run_id = p.evaluate("() => new URLSearchParams(location.hash.split('?')[1]).get('run')")
    options = httpx.get(f"{live_server}/api/v1/runs/{run_id}", timeout=30).json()["options"]
    assert options["checks"] == ["twist"]
    assert options["filter_method"] == "butterworth"
    assert options["filter_params"] == {"cutoff_hz": 4}
    assert options["max_points"] == 300


def trc_with_a_gap(corpus_dir: Path, folder: Path) -> Path:
    """The Pose2Sim balancing TRC with RWrist blanked in frames 40–49 (file numbering)."""
    lines = (corpus_dir / TRC_TAKE).read_text().splitlines()
    names = lines[3].split("\t")[2:]
    wrist = [n for n in names if n].index("RWrist")
    out = []
    for k, line in enumerate(lines):
        cells = line.split("\t")
        if k >= 5 and 40 <= int(cells[0]) <= 49:
            for c in range(2 + 3 * wrist, 5 + 3 * wrist):
                cells[c] = ""
        out.append("\t".join(cells))
    path = folder / "balancing_wrist_gap.trc"
    path.write_text("\n".join(out) + "\n")
    return path


def filter_run(server: str, take_id: str) -> dict[str, Any]:
    """A run of the filter alone on a take: its ``run`` id and ``result``."""
    created = httpx.post(f"{server}/api/v1/takes/{take_id}/runs", json={"checks": ["filter"]})
    created.raise_for_status()
    run_id = created.json()["id"]
    deadline = time.monotonic() + 120
    while httpx.get(f"{server}/api/v1/runs/{run_id}").json()["status"] not in ("done", "failed"):
        assert time.monotonic() < deadline
        time.sleep(0.3)
    return {"run": run_id, "result": httpx.get(f"{server}/api/v1/runs/{run_id}/result").json()}


def test_keypoint_confidence_fades_and_bridged_gaps_show(
    live_server: str, corpus_dir: Path, tmp_path: Path, page: Page
) -> None:
    p = page.page
    uploaded = upload(live_server, trc_with_a_gap(corpus_dir, tmp_path))
    # The filter alone: the default run's markers step would fill the gap before the filter.
    take = {**uploaded, **filter_run(live_server, uploaded["id"])}
    names = take["result"]["points"]["names"]
    wrist = names.index("RWrist")
    assert take["result"]["series"]["filter"]["bridged_runs"] == [[39, 48]]
    page.open_take(live_server, take, frame=44)
    # The gap is hatched on the time bar, over frames 39–48.
    gap = p.locator("#timebar .tb-gap")
    assert gap.count() == 1
    assert gap.get_attribute("title") == "bridged gap: frames 39–48"
    bar, mark = p.locator("#timebar").bounding_box(), gap.bounding_box()
    n_frames = take["result"]["summary"]["n_frames"]
    assert (mark["x"] - bar["x"]) / bar["width"] == pytest.approx(39 / n_frames, abs=0.01)
    # In the filtered view the bridged wrist says so on hover, with its confidence (0: missing).
    p.locator("#views").scroll_into_view_if_needed()
    page.settle()
    x, y = p.evaluate("(j) => window.mocapqaViews.screenOf('corrected', j)", wrist)
    p.mouse.move(x, y)
    p.wait_for_selector(".joint-tooltip:not([hidden])")
    assert p.inner_text(".joint-tooltip") == "RWrist · confidence 0.00 · bridged"
    # Outside the gap the same wrist is a full-confidence detection.
    scrub(page, 20)
    x, y = p.evaluate("(j) => window.mocapqaViews.screenOf('corrected', j)", wrist)
    p.mouse.move(x + 1, y)
    p.mouse.move(x, y)
    p.wait_for_function(
        "() => document.querySelector('.joint-tooltip').textContent.includes('1.00')"
    )
    scrub(page, 44)
    x, y = p.evaluate("(j) => window.mocapqaViews.screenOf('corrected', j)", wrist)
    p.mouse.move(x, y + 1)
    p.mouse.move(x, y)
    p.wait_for_function(
        "() => document.querySelector('.joint-tooltip').textContent.includes('bridged')"
    )
    shot(page, "keypoint-gap")


def test_a_short_window_unpins_the_player_bar(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    """At 200 % zoom (a 640×360 window in CSS pixels) a pinned player bar hid most of the 3D
    views; below 760 px of height it sits in the page's flow instead, and above it stays
    pinned to the bottom while the findings scroll."""
    p = page.page
    page.open_take(live_server, knees)
    position = "() => getComputedStyle(document.getElementById('player')).position"
    assert p.evaluate(position) == "sticky"
    p.set_viewport_size({"width": 640, "height": 360})
    p.wait_for_function(f"({position})() === 'static'")
    views = p.evaluate(
        "() => { const v = document.querySelector('canvas').getBoundingClientRect();"
        " const b = document.getElementById('player').getBoundingClientRect();"
        " return [v.bottom, b.top]; }"
    )
    assert views[0] <= views[1]  # the bar below the views, not over them
    # Nothing scrolls sideways once the charts have followed the narrow window.
    p.wait_for_function("() => document.documentElement.scrollWidth <= window.innerWidth")
    p.screenshot(path=str(ARTIFACTS / "take-short-window.png"))
    p.set_viewport_size({"width": 1280, "height": 900})
    p.wait_for_function(f"({position})() === 'sticky'")
    p.wait_for_function("() => document.documentElement.scrollWidth <= window.innerWidth")


def test_the_time_bar_is_a_slider_the_keyboard_reaches(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    """Tab reaches the time bar; Home/End go to the ends, Page Down a tenth further, the arrows
    step; a screen reader hears the frame."""
    p = page.page
    page.open_take(live_server, knees)
    n_frames = int(p.get_attribute("#timebar", "aria-valuemax")) + 1
    value = "() => document.getElementById('timebar').getAttribute('aria-valuenow')"
    p.focus("#timebar")
    assert p.get_attribute("#timebar", "role") == "slider"
    assert p.get_attribute("#timebar", "tabindex") == "0"
    p.keyboard.press("End")
    p.wait_for_function(f"() => ({value})() === '{n_frames - 1}'")
    assert page.frame() == n_frames - 1
    p.keyboard.press("Home")
    p.wait_for_function(f"() => ({value})() === '0'")
    p.keyboard.press("PageDown")
    step = int(n_frames / 10 + 0.5)  # as Math.round
    p.wait_for_function(f"() => ({value})() === '{step}'")
    p.keyboard.press("ArrowRight")
    assert page.frame() == step + 1
    assert p.get_attribute("#timebar", "aria-valuetext") == f"frame {step + 1} of {n_frames}"
    # The findings' skip button reaches the review past every row's Tab stops.
    p.focus("#skip-to-review")
    p.keyboard.press("Enter")
    assert p.evaluate("() => document.activeElement.id") == "review-status"
    p.focus("#timebar")
    # Space on the bar plays and pauses, as it does on the page.
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('pause')")
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('play')")
