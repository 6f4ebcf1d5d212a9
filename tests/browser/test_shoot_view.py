"""The shoot view in headless Chromium, on real takes of the corpus: import a folder into a new
shoot, watch the analysis finish, sort, walk the review queue with the keyboard, export CSV.

Screenshots go to ``tests/artifacts/shoot-*.png`` (gitignored). Time bounds are generous.
"""

from __future__ import annotations

import csv
import io
import shutil
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.store.skating_take import drifted_bvh

from mocapqa.api.routes.shoots import EXPORT_COLUMNS
from mocapqa.jobs.demo import demo_paths

pytestmark = pytest.mark.browser

ARTIFACTS = Path(__file__).resolve().parents[1] / "artifacts"
TAKES = (
    "bvh/bandai/dataset-1_dash_normal_001.bvh",
    "bvh/cmu/cmu_12_01_walk.bvh",
    "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc",
)
"""Real corpus takes; the bundled demo walk with injected twist errors joins them, so the
scores differ."""
ANALYSIS_MS = 300_000


class Page:
    """A Playwright page that records console errors and failed requests."""

    def __init__(self, chromium: Any, width: int = 1400, height: int = 1000) -> None:
        self.page = chromium.new_page(
            viewport={"width": width, "height": height}, accept_downloads=True
        )
        self.errors: list[str] = []
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))

    def open(self, url: str) -> None:
        self.page.goto(url)
        self.page.wait_for_selector("main[data-ready='1']", timeout=60_000)

    def no_sideways_scroll(self) -> bool:
        return bool(
            self.page.evaluate(
                "() => document.scrollingElement.scrollWidth"
                " <= document.scrollingElement.clientWidth"
            )
        )


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium, width=1600)  # every column shows from 1440 px
    yield opened
    assert opened.errors == []
    opened.page.close()


@pytest.fixture
def take_folder(corpus_dir: Path, tmp_path: Path) -> Path:
    """A folder of four takes, one in a sub-folder, and a file that is no take."""
    folder = tmp_path / "day1"
    (folder / "more").mkdir(parents=True)
    for k, relative in enumerate(TAKES):
        target = folder / ("more" if k == 2 else "") / Path(relative).name
        shutil.copyfile(corpus_dir / relative, target)
    twist_demo = demo_paths()[0]
    assert twist_demo.name.endswith("_twist_errors.bvh")
    shutil.copyfile(twist_demo, folder / twist_demo.name)
    (folder / "notes.txt").write_text("slate notes, not a take\n")
    return folder


def scores(page: Page) -> list[float]:
    texts = page.page.locator("#shoot-takes tbody .score").all_inner_texts()
    return [float(t) for t in texts]


def test_import_progress_sort_review_export(
    live_server: str, chromium: Any, page: Page, take_folder: Path
) -> None:
    ARTIFACTS.mkdir(exist_ok=True)
    p = page.page
    page.open(f"{live_server}/#/shoots")
    p.fill("#shoot-name", "Day 1")
    p.click("#shoot-create button[type=submit]")
    p.wait_for_url("**/#/shoot/*")
    p.wait_for_selector("main[data-ready='1'] #import-zone", timeout=60_000)
    shoot_id = p.url.split("#/shoot/")[1].split("?")[0]

    # Import the whole folder through the folder picker (webkitdirectory).
    p.set_input_files("#import-folder", take_folder)
    p.wait_for_selector("#import-kept", timeout=120_000)
    assert "kept (4)" in p.inner_text("#import-kept")
    rejected = p.inner_text("#import-skipped") + p.inner_text("#import-failed")
    assert "notes.txt" in rejected

    # While the takes are analysed the table is redrawn every second: a focused take row keeps
    # the focus (by its take id) instead of losing it to the page.
    p.wait_for_selector("#shoot-takes tbody tr[data-take]", timeout=60_000)
    p.focus("#shoot-takes tbody tr[data-take]")
    focused_take = p.evaluate(
        "() => { const row = document.activeElement; row.dataset.before = '1';"
        " return row.dataset.take; }"
    )
    if p.get_attribute("#progress-panel", "data-finished") == "0":  # a redraw is still to come
        p.wait_for_function(
            "() => !document.querySelector('#shoot-takes tr[data-before]')", timeout=60_000
        )
        assert p.evaluate("() => document.activeElement.dataset.take") == focused_take

    # Live progress: the bar reaches "done" without a reload.
    p.wait_for_selector("#progress-panel[data-finished='1']", timeout=ANALYSIS_MS)
    p.wait_for_function(
        "() => document.getElementById('shoot-progress-text').textContent"
        ".startsWith('4 of 4 takes analysed')",
        timeout=30_000,
    )
    p.wait_for_function(
        "() => document.querySelectorAll('#shoot-takes tbody tr').length === 4", timeout=30_000
    )
    assert p.locator("#shoot-takes tbody .badge.done").count() == 4
    p.screenshot(path=str(ARTIFACTS / "shoot-table.png"), full_page=True)

    # Sort by score: the default is ascending; a click on the header turns it around.
    ascending = scores(page)
    assert ascending == sorted(ascending)
    assert len(set(ascending)) > 1  # the twist errors cost the demo walk points
    p.click("#shoot-takes th[data-sort='score']")
    p.wait_for_selector("#shoot-takes th[data-sort='score'][aria-sort='descending']")
    assert scores(page) == sorted(ascending, reverse=True)
    assert "order=desc" in p.url
    # Sort by name from the keyboard (headers are focusable).
    p.focus("#shoot-takes th[data-sort='name']")
    p.keyboard.press("Enter")
    p.wait_for_selector("#shoot-takes th[data-sort='name'][aria-sort='ascending']")
    assert p.evaluate("() => document.activeElement.dataset.sort") == "name"
    names = p.locator("#shoot-takes tbody td.name").all_inner_texts()
    assert names == sorted(names)
    # Every column sorts on the server, both ways.
    columns = p.locator("#shoot-takes th[data-sort]").evaluate_all(
        "(ths) => ths.map((th) => th.dataset.sort)"
    )
    assert len(columns) == 19
    assert "limb_spins" in columns
    assert "foot_worst_skate" in columns
    for column in columns:
        header = f"#shoot-takes th[data-sort='{column}']"
        for _ in range(2):
            now = p.get_attribute(header, "aria-sort")
            order = "descending" if now == "ascending" else "ascending"
            p.click(header)
            p.wait_for_selector(f"{header}[aria-sort='{order}']")
            assert p.locator("#shoot-table-area .error").count() == 0
            assert p.locator("#shoot-takes tbody tr").count() == 4
    # Search filters on the server.
    p.fill("#shoot-search", "dash")
    p.wait_for_function(
        "() => document.querySelectorAll('#shoot-takes tbody tr').length === 1", timeout=30_000
    )
    assert p.inner_text("#page-info") == "1–1 of 1"
    # The score bounds are labelled; a min score above the max score is said beside them, and
    # the table lists nothing (no silent "0–0 of 0").
    assert p.inner_text("label[for='shoot-min_score']").strip() == "min score"
    assert p.inner_text("label[for='shoot-max_score']").strip() == "max score"
    p.fill("#shoot-min_score", "95")
    p.fill("#shoot-max_score", "50")
    p.wait_for_selector("#shoot-table-empty", timeout=30_000)
    assert p.inner_text("#shoot-score-message").startswith("min score (95) is above max score (50)")
    assert p.get_attribute("#shoot-min_score", "aria-invalid") == "true"
    assert p.locator("#page-info").count() == 0
    p.fill("#shoot-max_score", "")
    p.wait_for_selector("#page-info", timeout=30_000)
    assert p.inner_text("#shoot-score-message") == ""
    assert p.get_attribute("#shoot-min_score", "aria-invalid") == "false"
    p.fill("#shoot-min_score", "")
    p.wait_for_function(
        "() => !document.getElementById('shoot-table-area').dataset.query.includes('min_score')"
        " && document.getElementById('page-info')?.innerText === '1–1 of 1'",
        timeout=30_000,
    )

    # The review queue, lowest score first, walked with A, F, R.
    p.click("#review-queue")
    p.wait_for_selector("main[data-ready='1'] #queue-card[data-take]", timeout=30_000)
    # No reviewer field: the server records the signed-in user, and the page says who.
    assert p.locator("#queue-reviewer").count() == 0
    assert "Reviews are recorded as anonymous" in p.inner_text("#queue-who")
    p.click("h1")
    assert "A approve" in p.inner_text("#keys-help")
    p.keyboard.press("?")
    assert p.locator("#keys-help").count() == 1
    assert p.locator("#keys-help").is_hidden()
    p.keyboard.press("?")
    assert p.locator("#keys-help").is_visible()
    seen = []
    queue_scores = []
    for step, key in enumerate(("a", "f", "r", "a")):
        take = p.get_attribute("#queue-card", "data-take")
        seen.append(take)
        queue_scores.append(float(p.inner_text("#queue-score")))
        if step == 0:
            p.screenshot(path=str(ARTIFACTS / "shoot-review-queue.png"), full_page=True)
        if step == 1:
            p.fill("#queue-notes", "left wrist pops at the turn")
            p.click("h1")
        p.keyboard.press(key)
        p.wait_for_function(
            "(t) => document.getElementById('queue-card').dataset.take !== t", arg=take
        )
    p.wait_for_selector("#queue-done")
    assert len(set(seen)) == 4
    assert queue_scores == sorted(queue_scores)
    rows = httpx.get(f"{live_server}/api/v1/shoots/{shoot_id}/takes", timeout=30).json()["items"]
    decided = {r["take_id"]: (r["review_status"], r["reviewer"]) for r in rows}
    reviews = httpx.get(f"{live_server}/api/v1/takes/{seen[1]}", timeout=30).json()["reviews"]
    assert reviews[0]["notes"] == "left wrist pops at the turn"
    # The reviewer is the signed-in user, never the typed name: with no users configured the
    # server is open and every request acts as "anonymous".
    assert [decided[t] for t in seen] == [
        ("approved", "anonymous"),
        ("needs_fix", "anonymous"),
        ("rejected", "anonymous"),
        ("approved", "anonymous"),
    ]

    # Export the summary as CSV from the shoot view.
    page.open(f"{live_server}/#/shoot/{shoot_id}")
    with p.expect_download() as download_info:
        p.click("#export-csv")
    download = download_info.value
    text = Path(download.path()).read_text()
    table = list(csv.reader(io.StringIO(text)))
    assert table[0] == list(EXPORT_COLUMNS)
    assert len(table) == 1 + 4
    assert p.get_attribute("#export-json", "href").endswith("/summary.json?sort=score&order=asc")
    # Filtered, the downloads hold the table's takes only, and say so.
    p.select_option("#shoot-review_status", "approved")
    p.wait_for_function("document.getElementById('export-csv').textContent.startsWith('filtered')")
    with p.expect_download() as download_info:
        p.click("#export-csv")
    only = list(csv.DictReader(io.StringIO(Path(download_info.value.path()).read_text())))
    assert sorted(r["review_status"] for r in only) == ["approved", "approved"]
    p.select_option("#shoot-review_status", "")
    p.wait_for_function("document.getElementById('export-csv').textContent === 'summary CSV'")
    # The heat map follows the filters too: wait for it to hold every take again.
    p.wait_for_function(
        "() => document.getElementById('heatmap-chart')?.data?.[0]?.y?.length === 4",
        timeout=60_000,
    )

    # The heat map (Plotly, loaded by this view only): one row per take, lowest score first;
    # the keypoint take, which has no joint limits, is an empty row.
    p.wait_for_selector("#heatmap-chart .main-svg", timeout=60_000)
    joints, rows = p.evaluate(
        "() => { const d = document.getElementById('heatmap-chart').data[0];"
        " return [d.x, d.y.map((label, k) => [label, d.z[k]])]; }"
    )
    # One cell per joint in every row, the empty row too.
    assert joints
    assert [len(z) for _, z in rows] == [len(joints)] * 4
    assert [label.split(". ", 1)[0] for label, _ in rows] == ["1", "2", "3", "4"]  # ranks
    rows = [[label.split(". ", 1)[1], z] for label, z in rows]
    assert rows[0][0] == "cmu_12_01_walk_twist_errors.bvh"
    assert p.inner_text("#heatmap-page") == "takes 1–4 of 4"
    assert p.is_disabled("#heatmap-next")
    by_name = dict(rows)
    assert max(by_name["cmu_12_01_walk_twist_errors.bvh"]) > 0
    assert all(v is None for v in by_name[Path(TAKES[2]).name])
    assert all(v == 0 for v in by_name["cmu_12_01_walk.bvh"])
    p.screenshot(path=str(ARTIFACTS / "shoot-heatmap.png"), full_page=True)

    # The heat map follows the table: its sort and order, then its filters, from the first page.
    p.click("#shoot-takes th[data-sort='score']")  # ascending already: now descending
    p.wait_for_selector("#shoot-takes th[data-sort='score'][aria-sort='descending']")
    p.wait_for_function(
        "() => { const d = document.getElementById('heatmap-chart')?.data?.[0];"
        " return !!d && d.y.length === 4"
        " && d.y[3].endsWith('cmu_12_01_walk_twist_errors.bvh'); }",
        timeout=60_000,
    )
    assert "order=desc" in (p.get_attribute("#shoot-heatmap", "data-query") or "")
    down = p.evaluate("() => document.getElementById('heatmap-chart').data[0].y")
    table_names = p.locator("#shoot-takes tbody td.name").all_inner_texts()
    assert [label.split(". ", 1)[1] for label in down] == table_names
    assert table_names[-1] == "cmu_12_01_walk_twist_errors.bvh"
    p.fill("#shoot-search", "walk")
    p.wait_for_function(
        "() => document.getElementById('heatmap-page')?.innerText === 'takes 1–2 of 2'"
        " && document.getElementById('heatmap-chart')?.data?.[0]?.y?.length === 2",
        timeout=60_000,
    )
    walks = p.evaluate("() => document.getElementById('heatmap-chart').data[0].y")
    assert [label.split(". ", 1)[1] for label in walks] == [
        "cmu_12_01_walk.bvh",
        "cmu_12_01_walk_twist_errors.bvh",
    ]
    query = p.get_attribute("#shoot-heatmap", "data-query") or ""
    assert "search=walk" in query
    assert "order=desc" in query
    p.select_option("#shoot-has_findings", "true")
    p.wait_for_function(
        "() => document.getElementById('heatmap-page')?.innerText === 'takes 1–1 of 1'",
        timeout=60_000,
    )
    p.fill("#shoot-search", "no such take")
    p.wait_for_selector("#heatmap-empty", timeout=60_000)
    assert p.inner_text("#heatmap-empty") == "No take matches the table's filters."
    # The filters live in the view's URL: a fresh load draws the heat map with them.
    page.open(f"{live_server}/#/shoot/{shoot_id}?search=walk&sort=name")
    p.wait_for_function(
        "() => document.getElementById('heatmap-chart')?.data?.[0]?.y?.length === 2",
        timeout=60_000,
    )
    assert p.inner_text("#heatmap-page") == "takes 1–2 of 2"
    p.screenshot(path=str(ARTIFACTS / "shoot-heatmap-filtered.png"), full_page=True)

    # The shoots list counts the takes per run status.
    page.open(f"{live_server}/#/shoots")
    row = p.locator(f"#shoot-list tr[data-shoot='{shoot_id}'] td").all_inner_texts()
    assert row[:2] == ["Day 1", "4"]
    assert row[3:7] == ["0", "0", "4", "0"]  # queued, running, done, failed
    p.screenshot(path=str(ARTIFACTS / "shoot-list.png"), full_page=True)

    # A 900 px window scrolls only down. It hides the secondary columns (below 1440 px), and
    # "all columns" shows them: the table then scrolls inside its box, never the page.
    narrow = Page(chromium, width=900, height=900)
    narrow.open(f"{live_server}/#/shoot/{shoot_id}")
    narrow.page.wait_for_selector("#shoot-takes tbody tr")
    narrow.page.wait_for_selector("#shoot-heatmap h2", timeout=60_000)
    assert narrow.no_sideways_scroll()
    narrow.page.screenshot(path=str(ARTIFACTS / "shoot-900px.png"), full_page=True)
    rig = "#shoot-takes th[data-sort='rig']"
    assert narrow.page.is_hidden(rig)
    narrow.page.focus("#shoot-all-columns")
    narrow.page.keyboard.press("Enter")
    narrow.page.wait_for_selector(rig, state="visible")
    assert narrow.page.get_attribute("#shoot-all-columns", "aria-pressed") == "true"
    assert narrow.page.locator("#shoot-takes thead th:visible").count() == 20
    assert narrow.no_sideways_scroll()
    narrow.page.screenshot(path=str(ARTIFACTS / "shoot-900px-all-columns.png"), full_page=True)
    narrow.page.keyboard.press("Enter")
    narrow.page.wait_for_selector(rig, state="hidden")
    narrow.open(f"{live_server}/#/shoots")
    assert narrow.no_sideways_scroll()
    assert narrow.errors == []
    narrow.page.close()


def test_archive_and_broken_file_show_kept_skipped_and_failed(
    live_server: str, page: Page, corpus_dir: Path, tmp_path: Path
) -> None:
    shoot = httpx.post(f"{live_server}/api/v1/shoots", json={"name": "Archive day"}, timeout=30)
    shoot.raise_for_status()
    archive = tmp_path / "day2.zip"
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.write(corpus_dir / TAKES[0], f"takes/{Path(TAKES[0]).name}")
        bundle.writestr("takes/slate.txt", "not a take")
    broken = tmp_path / "broken.bvh"
    broken.write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n")
    page.open(f"{live_server}/#/shoot/{shoot.json()['id']}")
    page.page.set_input_files("#import-files", [archive, broken])
    page.page.wait_for_selector("#import-kept", timeout=120_000)
    assert "kept (1)" in page.page.inner_text("#import-kept")
    assert "day2.zip:takes/slate.txt: not a motion file" in page.page.inner_text("#import-skipped")
    failed = page.page.inner_text("#import-failed")
    assert "failed (1)" in failed
    assert "broken.bvh" in failed
    page.page.wait_for_selector("#progress-panel[data-finished='1']", timeout=ANALYSIS_MS)
    page.page.wait_for_selector("#shoot-takes tbody tr .badge.done", timeout=30_000)
    page.page.screenshot(path=str(ARTIFACTS / "shoot-import-result.png"), full_page=True)


def test_dropped_files_are_imported(live_server: str, page: Page, corpus_dir: Path) -> None:
    """Two takes dropped on the drop zone, one of them the twist-error walk under a
    240-character name: the names wrap, the heat map keeps its cells and labels every joint."""
    shoot = httpx.post(f"{live_server}/api/v1/shoots", json={"name": "Drop day"}, timeout=30)
    shoot.raise_for_status()
    page.open(f"{live_server}/#/shoot/{shoot.json()['id']}")
    take = corpus_dir / TAKES[0]
    long_name = "take_" + "very_long_name_" * 15 + "end_of_it.bvh"
    dropped = page.page.evaluate_handle(
        "(files) => { const d = new DataTransfer();"
        " for (const [name, text] of files) d.items.add(new File([text], name)); return d; }",
        [[take.name, take.read_text()], [long_name, demo_paths()[0].read_text()]],
    )
    page.page.dispatch_event("#import-zone", "drop", {"dataTransfer": dropped})
    page.page.wait_for_selector("#import-kept", timeout=120_000)
    kept = page.page.inner_text("#import-kept")
    assert "kept (2)" in kept
    assert take.name in kept
    assert long_name in kept
    page.page.wait_for_function(
        "() => document.querySelectorAll('#shoot-takes tbody .badge.done').length === 2",
        timeout=ANALYSIS_MS,
    )

    # At 800 px: the long name wraps (import list, table), nothing scrolls the page sideways.
    p = page.page
    p.set_viewport_size({"width": 800, "height": 900})
    p.wait_for_selector("#heatmap-chart .main-svg", timeout=60_000)
    p.wait_for_function(
        "() => document.getElementById('heatmap-chart')?.data?.[0]?.y?.length === 2",
        timeout=60_000,
    )
    # Plotly follows the window (responsive): the cells end inside the heat map's box again.
    p.wait_for_function(
        "() => document.querySelector('#heatmap-chart .nsewdrag').getBoundingClientRect().right"
        " <= document.getElementById('heatmap-scroll').getBoundingClientRect().right",
        timeout=30_000,
    )
    assert page.no_sideways_scroll()
    # The import list and the takes table show the name in full, wrapped over lines that end
    # inside the window.
    shown = p.evaluate(
        """(name) => [...document.querySelectorAll('#import-kept li, #shoot-takes td.name')]
          .filter((el) => el.textContent.includes(name.slice(0, 40))).map((el) => {
            const text = document.createRange();
            text.selectNodeContents(el);
            const boxes = [...text.getClientRects()];
            return { where: el.tagName, text: el.textContent,
              lines: new Set(boxes.map((b) => Math.round(b.top))).size,
              right: Math.max(...boxes.map((b) => b.right)), window: window.innerWidth }; })""",
        long_name,
    )
    assert [s["where"] for s in shown] == ["LI", "TD"], shown
    for seen in shown:
        assert seen["text"] == long_name, seen
        assert seen["lines"] >= 2, seen
        assert seen["right"] <= seen["window"], seen
    heat = p.evaluate(
        """() => { const chart = document.getElementById('heatmap-chart');
          const d = chart.data[0];
          const cells = chart.querySelector('.nsewdrag').getBoundingClientRect();
          const box = document.getElementById('heatmap-scroll').getBoundingClientRect();
          const labels = (axis) => [...chart.querySelectorAll(`.${axis}tick text`)]
            .map((t) => t.textContent);
          return { y: d.y, x: d.x, text: d.text, width: cells.width, right: cells.right,
            box: box.right, bottom: labels('x'), top: labels('x2') }; }"""
    )
    row = next(k for k, label in enumerate(heat["y"]) if "very_long" in label)
    assert len(heat["y"][row]) <= 40
    assert heat["y"][row].startswith(f"{row + 1}. take_very_long")
    assert heat["y"][row].endswith("end_of_it.bvh")
    # The hover names it in full, in lines that fit the window.
    assert heat["text"][row][0].replace("<br>", "") == f"{row + 1}. {long_name}"
    # Every joint labelled, below and above the cells; the cells keep their width.
    assert heat["x"]
    assert heat["bottom"] == heat["x"]
    assert heat["top"] == heat["x"]
    assert heat["width"] >= 26 * len(heat["x"])
    p.screenshot(path=str(ARTIFACTS / "shoot-long-name-800px.png"), full_page=True)


def test_feet_columns_show_sort_and_filter_the_skates(
    live_server: str, page: Page, corpus_dir: Path, tmp_path: Path
) -> None:
    """A shoot with a real BVH take given a slide (its root drifts while both feet are planted),
    a keypoint take whose skate is in cm, a take with none and a take whose latest run did not
    check the feet: the skate columns say their unit in the header, sort on the server, filter,
    and show a dash (not 0) where there is no figure."""
    base = f"{live_server}/api/v1"
    shoot = httpx.post(f"{base}/shoots", json={"name": "Feet day"}, timeout=30)
    shoot.raise_for_status()
    sid = shoot.json()["id"]
    skating = drifted_bvh(corpus_dir, tmp_path)
    paths = [skating, *(corpus_dir / p for p in (TAKES[2], TAKES[0], TAKES[1]))]
    files = [("files", (path.name, path.read_bytes())) for path in paths]
    imported = httpx.post(f"{base}/shoots/{sid}/takes", files=files, timeout=120)
    assert imported.status_code == 201, imported.text
    unchecked = next(c for c in imported.json()["created"] if c["name"] == paths[3].name)
    page.open(f"{live_server}/#/shoot/{sid}")
    p = page.page
    p.wait_for_selector("#progress-panel[data-finished='1']", timeout=ANALYSIS_MS)
    again = httpx.post(
        f"{base}/takes/{unchecked['take_id']}/runs",
        json={"checks": ["twist", "limits"]},
        timeout=30,
    )
    assert again.status_code == 201, again.text
    page.open(f"{live_server}/#/shoot/{sid}?sort=foot_worst_skate&order=desc")
    p.wait_for_selector("#progress-panel[data-finished='1']", timeout=ANALYSIS_MS)
    p.wait_for_function(
        "() => document.querySelectorAll('#shoot-takes tbody .badge.done').length === 4",
        timeout=ANALYSIS_MS,
    )
    header = p.inner_text("#shoot-takes th[data-sort='foot_worst_skate']")
    assert header.startswith("worst skate")
    assert "cm" not in header
    assert p.get_attribute("#shoot-takes th[data-sort='foot_worst_skate']", "aria-sort") == (
        "descending"
    )
    rows = httpx.get(
        f"{base}/shoots/{sid}/takes", params={"sort": "foot_worst_skate", "order": "desc"}
    ).json()["items"]
    api_names = [r["name"] for r in rows]
    assert p.locator("#shoot-takes tbody td.name").all_inner_texts() == api_names

    def cells(name: str) -> dict[str, str]:
        row = p.locator("#shoot-takes tbody tr", has=p.locator("td.name", has_text=name))
        keys = p.locator("#shoot-takes th[data-sort]").evaluate_all(
            "(ths) => ths.map((th) => th.dataset.sort)"
        )
        texts = row.locator("td").all_inner_texts()[1:]  # after the thumbnail
        return dict(zip(keys, texts, strict=True))

    bvh = next(r for r in rows if r["name"] == paths[0].name)
    shown = cells(paths[0].name)
    assert bvh["foot_skate_unit"] == "% height"
    assert shown["foot_skates"] == str(bvh["foot_skates"])
    # The count is the run's skate findings (what the take view's findings list shows).
    result = httpx.get(f"{base}/runs/{bvh['run_id']}/result", timeout=30).json()
    skates = [f for f in result["findings"] if f["kind"] == "skate"]
    assert bvh["foot_skates"] == len(skates) >= 1
    assert bvh["foot_worst_skate"] == max(f["value"] for f in skates)
    assert shown["foot_worst_skate"] == f"{bvh['foot_worst_skate']:.1f} % height"
    assert bvh["foot_worst_skate_pct"] == bvh["foot_worst_skate"]  # % height already
    trc_row = next(r for r in rows if r["name"] == paths[1].name)
    trc = cells(paths[1].name)
    # cm, said in the cell, with the share of the body height beside it when the row has it.
    share = trc_row["foot_worst_skate_pct"]
    assert trc["foot_worst_skate"] == f"{trc_row['foot_worst_skate']:.1f} cm" + (
        "" if share is None else f" ({share:.1f} % height)"
    )
    clean = cells(paths[2].name)
    assert (clean["foot_skates"], clean["foot_worst_skate"]) == ("0", "–")
    # The take whose run did not check the feet: a dash in every feet cell, never 0. The
    # column sorts by the share of the body height (the one measure of takes in cm and in %
    # height): largest first, takes without one last (by name) in either order.
    valued = [r for r in rows if r["foot_worst_skate_pct"] is not None]
    assert [r["foot_worst_skate_pct"] for r in valued] == sorted(
        (r["foot_worst_skate_pct"] for r in valued), reverse=True
    )
    assert api_names[len(valued) :] == sorted(
        r["name"] for r in rows if r["foot_worst_skate_pct"] is None
    )
    assert {paths[2].name, paths[3].name} <= set(api_names[len(valued) :])
    assert [cells(paths[3].name)[k] for k in ("foot_skates", "foot_worst_skate")] == ["–", "–"]
    ARTIFACTS.mkdir(exist_ok=True)
    p.screenshot(path=str(ARTIFACTS / "shoot-feet-columns.png"), full_page=True)

    # Sorting by the skate count from the header; the skates filter keeps the two skating takes.
    p.click("#shoot-takes th[data-sort='foot_skates']")
    p.wait_for_selector("#shoot-takes th[data-sort='foot_skates'][aria-sort='ascending']")
    counts = [
        cells(n)["foot_skates"] for n in p.locator("#shoot-takes tbody td.name").all_inner_texts()
    ]
    assert counts[-1] == "–"
    assert [int(c) for c in counts[:-1]] == sorted(int(c) for c in counts[:-1])
    p.select_option("#shoot-has_skates", "true")
    p.wait_for_function(
        "() => document.getElementById('page-info')?.innerText === '1–2 of 2'", timeout=30_000
    )
    names = set(p.locator("#shoot-takes tbody td.name").all_inner_texts())
    assert names == {paths[0].name, paths[1].name}
    assert "has_skates=true" in p.url


TABLE_FIT = """() => {
  const table = document.getElementById('shoot-takes');
  const box = table.closest('.table-scroll');
  const heads = [...table.querySelectorAll('thead th')];
  const shown = heads.filter((th) => getComputedStyle(th).display !== 'none');
  const cells = [...table.querySelectorAll('tbody tr:first-child td')]
    .filter((td) => getComputedStyle(td).display !== 'none');
  const last = shown[shown.length - 1].getBoundingClientRect();
  const lastCell = cells[cells.length - 1].getBoundingClientRect();
  const page = document.scrollingElement;
  return { boxScroll: box.scrollWidth, boxClient: box.clientWidth,
    lastRight: Math.max(last.right, lastCell.right), window: window.innerWidth,
    pageFits: page.scrollWidth <= page.clientWidth,
    shown: shown.map((th) => th.dataset.sort || ''),
    hidden: heads.filter((th) => getComputedStyle(th).display === 'none')
      .map((th) => th.dataset.sort),
    toggle: getComputedStyle(document.getElementById('shoot-all-columns')).display !== 'none' };
}"""
"""Where the take table ends: its box's scroll and client widths, the right edge of its last
shown column (header and first row), the window's width, and the columns shown and hidden."""


def test_the_take_table_uses_a_wide_window_and_folds_below_1440_px(
    live_server: str, chromium: Any, corpus_dir: Path, tmp_path: Path
) -> None:
    """The widest cells a take table has (a skate in cm with its share of the height, in %
    height, a worst joint, a reviewer): at 1920 × 1080 every column shows and ends inside the
    window with no scroll in the table's box (the page is not held to 1,500 px); at 1440 px
    too; below it the secondary columns fold away and "all columns" brings them back in the
    box."""
    base = f"{live_server}/api/v1"
    shoot = httpx.post(f"{base}/shoots", json={"name": "Wide day"}, timeout=30)
    shoot.raise_for_status()
    sid = shoot.json()["id"]
    paths = [drifted_bvh(corpus_dir, tmp_path), corpus_dir / TAKES[2], corpus_dir / TAKES[1]]
    files = [("files", (path.name, path.read_bytes())) for path in paths]
    imported = httpx.post(f"{base}/shoots/{sid}/takes", files=files, timeout=120)
    assert imported.status_code == 201, imported.text
    for created in imported.json()["created"]:
        review = {"status": "needs_fix", "reviewer": "lead reviewer of the day"}
        answer = httpx.post(f"{base}/takes/{created['take_id']}/reviews", json=review, timeout=30)
        assert answer.status_code == 201, answer.text
    page = Page(chromium, width=1920, height=1080)
    p = page.page
    page.open(f"{live_server}/#/shoot/{sid}")
    p.wait_for_selector("#progress-panel[data-finished='1']", timeout=ANALYSIS_MS)
    p.wait_for_function(
        "() => document.querySelectorAll('#shoot-takes tbody .badge.done').length === 3",
        timeout=ANALYSIS_MS,
    )
    rows = httpx.get(f"{base}/shoots/{sid}/takes", timeout=30).json()["items"]
    assert {r["foot_skate_unit"] for r in rows} >= {"cm", "% height"}
    columns = p.locator("#shoot-takes th[data-sort]").evaluate_all(
        "(ths) => ths.map((th) => th.dataset.sort)"
    )
    ARTIFACTS.mkdir(exist_ok=True)
    for width in (1920, 1440):
        p.set_viewport_size({"width": width, "height": 1080 if width == 1920 else 900})
        p.wait_for_function(f"() => window.innerWidth === {width}")
        fit = p.evaluate(TABLE_FIT)
        assert fit["hidden"] == [], fit
        assert [k for k in fit["shown"] if k] == columns, fit
        assert fit["boxScroll"] <= fit["boxClient"], fit  # nothing scrolls in the box
        assert fit["lastRight"] <= fit["window"], fit  # the reviewer column is in view
        assert fit["pageFits"], fit
        assert not fit["toggle"], fit
        p.screenshot(path=str(ARTIFACTS / f"shoot-table-{width}px.png"), full_page=True)

    # Below 1440 px the secondary columns fold away (docs/dashboard.md); "all columns" shows
    # them again, in the table's box (which may then scroll), never the page.
    p.set_viewport_size({"width": 1439, "height": 900})
    p.wait_for_function("() => window.innerWidth === 1439")
    fit = p.evaluate(TABLE_FIT)
    narrow = {"duration_s", "rig", "limb_spins", "worst_joint", "filter_residual_mm",
              "missing_share", "foot_penetrations", "foot_floating", "reviewer"}  # fmt: skip
    assert set(fit["hidden"]) == narrow, fit
    assert fit["toggle"], fit
    assert fit["boxScroll"] <= fit["boxClient"], fit
    assert fit["lastRight"] <= fit["window"], fit
    p.click("#shoot-all-columns")
    p.wait_for_selector("#shoot-all-columns[aria-pressed='true']")
    fit = p.evaluate(TABLE_FIT)
    assert fit["hidden"] == [], fit
    assert fit["pageFits"], fit
    assert page.errors == []
    p.close()
