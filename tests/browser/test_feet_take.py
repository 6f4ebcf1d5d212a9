"""A BVH take with feet in the take view: its contact timeline under the time bar, a row per
foot with a bar per contact of the run's feet step, and the step's floor plane in both 3D
views (none for a run without the feet step)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import numpy as np
import pytest
from tests.browser.test_workstation import ARTIFACTS, Page, run_again, upload

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


def test_the_floor_plane_lies_at_the_feet_steps_floor_in_both_views(
    live_server: str, corpus_dir: Path, page: Page
) -> None:
    take = upload(live_server, corpus_dir / WALK)
    feet = take["result"]["series"]["feet"]
    assert feet["up_axis"] == "Y"
    page.open_take(live_server, take)
    p = page.page
    floor = p.evaluate("() => window.mocapqaViews.floorDrawn()")
    assert floor is not None
    assert floor["axis"] == 1
    assert floor["shown"] == [True, True]
    corners = np.asarray(floor["corners"]).reshape(4, 3)
    # The walk's floor is tilted (docs/feet.md): the plane drawn is the one the step fitted,
    # at `floor` where it passes through `plane_origin` (x, z).
    check = feet["floor_check"]
    assert check["tilted"]
    along = (corners[:, [0, 2]] - np.asarray(check["plane_origin"])) @ np.asarray(
        check["plane_gradient"]
    )
    np.testing.assert_allclose(corners[:, 1], feet["floor"] + along, atol=1e-4)
    # Over the walk's horizontal extent: the root's travel lies inside the plane.
    frames = httpx.get(
        f"{live_server}/api/v1/runs/{take['run']}/frames", params={"max_frames": 50}, timeout=60
    ).json()
    points = np.asarray(
        [[np.nan] * 3 if q is None else q for f in frames["raw"] for q in f], dtype=float
    )
    for axis in (0, 2):
        assert corners[:, axis].min() <= np.nanmin(points[:, axis])
        assert corners[:, axis].max() >= np.nanmax(points[:, axis])
    ARTIFACTS.mkdir(exist_ok=True)
    p.locator("#player").scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "feet-floor-plane.png"), full_page=False)
    # Turned off, neither view shows it.
    p.evaluate("() => window.mocapqaViews.setFloorShown(false)")
    assert p.evaluate("() => window.mocapqaViews.floorDrawn().shown") == [False, False]

    # A run without the feet step has no floor plane.
    other = run_again(live_server, take["id"], {"checks": ["twist"]})
    page.open_take(live_server, {**take, "run": other})
    assert p.evaluate("() => window.mocapqaViews.floorDrawn()") is None
    assert not page.errors, page.errors
