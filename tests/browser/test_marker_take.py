"""A C3D marker take in the take view: its gap timeline under the time bar, a filled sample
drawn in the corrected view, the segments as sticks, and the corrected C3D to download."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.browser.test_workstation import ARTIFACTS, Page, upload

pytestmark = pytest.mark.browser

C3D_TAKE = Path("c3d/optitrack/kinematics_tennis_serve_nan.c3d")


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def test_a_c3d_take_shows_its_gaps_and_filled_samples(
    live_server: str, corpus_dir: Path, page: Page
) -> None:
    take = upload(live_server, corpus_dir / C3D_TAKE)
    result = take["result"]
    assert result["steps"]["markers"]["state"] == "done"
    filled = [f for f in result["findings"] if f["kind"] == "gap"]
    left = [f for f in result["findings"] if f["kind"] == "gap not filled"]
    assert filled
    assert left
    assert result["points"]["bones"]  # the inferred segments' sticks
    downloads = httpx.get(f"{live_server}/api/v1/runs/{take['run']}/result").json()["downloads"]
    assert "c3d" in downloads
    corrected = httpx.get(f"{live_server}/api/v1/runs/{take['run']}/download/c3d", timeout=30)
    assert corrected.status_code == 200
    assert corrected.content[1] == 0x50  # a C3D's parameter-section mark

    gap = max(filled, key=lambda f: f["end_frame"] - f["start_frame"])
    middle = (gap["start_frame"] + gap["end_frame"]) // 2
    page.open_take(live_server, take, frame=middle)
    p = page.page
    # One row per marker with gaps; filled gaps outlined, the others solid.
    rows = p.locator("#gap-timeline .gt-row")
    assert rows.count() == len({f["joint"] for f in filled + left})
    row = p.locator(f"#gap-timeline .gt-row[data-marker='{gap['joint']}']")
    assert row.locator(".gt-bar.gt-filled").count()
    assert p.locator("#gap-timeline .gt-bar.gt-missing").count() == len(left)
    # At the gap's middle frame the corrected view draws its filled sample.
    p.wait_for_function("() => window.mocapqaViews.filledShown >= 1", timeout=30_000)
    assert p.inner_text("#view-legend").startswith("markers")
    assert "markers" in p.inner_text("#steps-list, .steps")
    assert p.locator("#download-c3d").count() == 1

    # A click on another gap's bar goes to its first frame.
    other = p.locator("#gap-timeline .gt-bar.gt-missing").first
    start = int(other.get_attribute("data-start") or -1)
    other.click()
    page.settle()
    assert page.frame() == start

    # Back at the gap's middle, zoomed in: hovering the filled marker says so.
    page.open_take(live_server, take, frame=middle)
    p.wait_for_function("() => window.mocapqaViews.filledShown >= 1", timeout=30_000)
    p.locator("#views").scroll_into_view_if_needed()
    box = p.locator("#view-corrected").bounding_box()
    assert box is not None
    p.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    p.mouse.wheel(0, -300)
    page.settle()
    marker = result["points"]["names"].index(gap["joint"])
    x, y = p.evaluate("(j) => window.mocapqaViews.screenOf('corrected', j)", marker)
    assert box["y"] < y < box["y"] + box["height"]
    p.mouse.move(x, y)
    p.wait_for_selector(".joint-tooltip:not([hidden])")
    assert p.inner_text(".joint-tooltip").endswith("· filled")
    assert p.inner_text(".joint-tooltip").startswith(gap["joint"])
    ARTIFACTS.mkdir(exist_ok=True)
    p.screenshot(path=str(ARTIFACTS / "marker-take.png"), full_page=False)
