"""A BVH take with feet in the take view: its contact timeline under the time bar, a row per
foot with a bar per contact of the run's feet step."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from tests.browser.test_workstation import ARTIFACTS, Page, upload

pytestmark = pytest.mark.browser

WALK = Path("bvh/cmu/cmu_12_01_walk.bvh")


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def test_a_walk_shows_the_contacts_of_each_foot(
    live_server: str, corpus_dir: Path, page: Page
) -> None:
    take = upload(live_server, corpus_dir / WALK)
    result = take["result"]
    assert result["steps"]["feet"]["state"] == "done"
    contacts = result["series"]["feet"]["contacts"]
    feet = [f for f in result["findings"] if "foot" in f]

    page.open_take(live_server, take)
    p = page.page
    rows = p.locator("#contact-timeline .ct-row")
    assert [rows.nth(k).get_attribute("data-foot") for k in range(rows.count())] == [
        "left",
        "right",
    ]
    for foot in ("left", "right"):
        row = p.locator(f"#contact-timeline .ct-row[data-foot='{foot}']")
        assert row.locator(".ct-bar").count() == sum(c["foot"] == foot for c in contacts) > 0
        assert row.locator(".ct-mark").count() == sum(f["foot"] == foot for f in feet)
    # The rows span the time bar frame for frame: the last contact ends at the take's end.
    bar = p.locator("#timebar").bounding_box()
    last = p.locator("#contact-timeline .ct-row[data-foot='right'] .ct-bar").last.bounding_box()
    assert bar is not None
    assert last is not None
    assert abs((last["x"] + last["width"]) - (bar["x"] + bar["width"])) < 3

    # A click on a contact goes to its first frame.
    bar = p.locator("#contact-timeline .ct-row[data-foot='left'] .ct-bar").nth(1)
    start = int(bar.get_attribute("data-start") or -1)
    bar.click()
    page.settle()
    assert page.frame() == start
    ARTIFACTS.mkdir(exist_ok=True)
    p.locator("#player").scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "feet-contacts.png"), full_page=False)
