"""The dashboard in Debian's Chromium (headless, through Playwright) against a real uvicorn
(``conftest.live_server``, its own per module).

Screenshots go to ``test-artifacts/`` at the repository root.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mocapqa.io.bvh import parse_bvh, read_bvh
from mocapqa.jobs.demo import demo_paths

pytestmark = pytest.mark.browser

ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts"


def drawn_points(page: object) -> int:
    """Points (joints and End Sites) the 3D views draw."""
    count = page.evaluate("() => window.mocapqaViews.points")  # type: ignore[attr-defined]
    return int(count)


def plotted_points(page: object, element_id: str, trace: int) -> int:
    count = page.evaluate(  # type: ignore[attr-defined]
        f"() => {{ const d = document.getElementById('{element_id}').data;"
        f" return d && d[{trace}] ? d[{trace}].x.length : 0; }}"
    )
    return int(count)


def upload_through_page(page: object, path: Path) -> None:
    # Hash navigation keeps the page (and Plotly, slow to evaluate) loaded.
    page.evaluate("() => { location.hash = '#/upload'; }")  # type: ignore[attr-defined]
    page.wait_for_selector("#file-input", state="attached")  # type: ignore[attr-defined]
    page.set_input_files("#file-input", str(path))  # type: ignore[attr-defined]
    page.wait_for_selector("#open-take", timeout=60_000)  # type: ignore[attr-defined]
    page.click("#open-take")  # type: ignore[attr-defined]
    page.wait_for_selector("main[data-ready='1']", timeout=30_000)  # type: ignore[attr-defined]


def test_upload_view_scrub_jump_review_and_download(
    live_server: str, chromium: object, cmu_walk: Path, tmp_path: Path
) -> None:
    ARTIFACTS.mkdir(exist_ok=True)
    page = chromium.new_page(viewport={"width": 1400, "height": 1000})  # type: ignore[attr-defined]
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))

    # A rejected upload shows the API's message, with the file's line.
    bad = tmp_path / "broken.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 zero\n")
    page.goto(f"{live_server}/#/upload")
    page.set_input_files("#file-input", str(bad))
    page.wait_for_selector("#upload-error")
    assert "broken.bvh, line 4" in page.inner_text("#upload-error")
    page.screenshot(path=str(ARTIFACTS / "upload-rejected.png"))
    errors.clear()  # the browser logs the 422 response itself

    # A real corpus take: both 3D views and the twist timeline are drawn.
    upload_through_page(page, cmu_walk)
    n_points = len(read_bvh(cmu_walk).skeleton.names) + len(read_bvh(cmu_walk).skeleton.end_sites)
    assert drawn_points(page) == n_points
    assert plotted_points(page, "chart-twist", 0) > 100
    page.screenshot(path=str(ARTIFACTS / "take-view.png"), full_page=True)

    # Scrubbing changes the frame shown in both views.
    page.evaluate(
        "() => { const s = document.getElementById('scrubber'); s.value = 300;"
        " s.dispatchEvent(new Event('input')); }"
    )
    assert page.inner_text("#frame-label").startswith("frame 300 /")
    assert page.inner_text("#panel-raw .view-title") == "raw — frame 300"

    # The demo take (CMU walk with injected twist errors): click a flagged interval.
    upload_through_page(page, demo_paths()[0])
    bars = page.locator("#chart-twist .barlayer .point path")
    assert bars.count() == 5  # the five injected intervals of the demo README
    bars.nth(2).click(force=True)
    label = page.inner_text("#frame-label")
    starts = [116, 134, 243, 328, 387]
    assert any(label.startswith(f"frame {s} /") for s in starts), label
    assert "0 flagged" not in label
    page.screenshot(path=str(ARTIFACTS / "take-view-flagged.png"), full_page=True)

    # A review status persists after reload.
    page.select_option("#review-status", "needs_fix")
    page.fill("#review-notes", "left arm twist")
    page.click("#review-save")
    page.wait_for_selector("#review-history li")
    page.reload()
    page.wait_for_selector("main[data-ready='1']", timeout=30_000)
    assert page.input_value("#review-status") == "needs_fix"
    assert "left arm twist" in page.inner_text("#review-history")

    # The corrected file downloads and parses.
    with page.expect_download() as info:
        page.click("#download-bvh")
    target = ARTIFACTS / "downloaded-corrected.bvh"
    info.value.save_as(str(target))
    corrected = parse_bvh(target.read_bytes(), target)
    assert corrected.n_frames == 523

    page.evaluate("() => { location.hash = '#/'; }")
    page.wait_for_selector("#take-list tbody tr")
    assert "needs fix" in page.inner_text("#take-list")
    page.screenshot(path=str(ARTIFACTS / "take-list.png"), full_page=True)
    assert errors == []
    page.close()
