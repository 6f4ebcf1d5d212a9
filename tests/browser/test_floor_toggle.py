"""The floor plane's checkbox in the take view: shown only with a floor, toggled by the keyboard
and the mouse in both 3D views, saying when the floor is tilted; a tilted floor drawn as the
plane the feet step fitted, a y-down floor at the feet."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import numpy as np
import pytest
from tests.browser.test_workstation import ARTIFACTS, Page, run_again, upload

pytestmark = pytest.mark.browser

WALK = Path("bvh/cmu/cmu_12_01_walk.bvh")  # its floor drops 0.58 units over the walk: tilted
MEDIAPIPE = Path("keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv")  # y down


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def shown(page: Page) -> list[bool]:
    return list(page.page.evaluate("() => window.mocapqaViews.floorDrawn().shown"))


def plane_at(feet: dict[str, Any], corners: np.ndarray) -> np.ndarray:
    """The coordinate on the up axis of the feet step's plane at each corner's horizontal point."""
    axis = "XYZ".index(feet["up_axis"][-1])
    sign = -1.0 if feet["up_axis"].startswith("-") else 1.0
    across = [a for a in range(3) if a != axis]
    check = feet["floor_check"]
    offset = (corners[:, across] - np.asarray(check["plane_origin"])) @ np.asarray(
        check["plane_gradient"]
    )
    return np.asarray(feet["floor"] + sign * offset)


def test_the_floor_checkbox_toggles_a_tilted_floor_by_keyboard_and_mouse(
    live_server: str, corpus_dir: Path, page: Page
) -> None:
    take = upload(live_server, corpus_dir / WALK)
    feet = take["result"]["series"]["feet"]
    check = feet["floor_check"]
    assert feet["up_axis"] == "Y"
    assert check["tilted"]
    assert check["plane_gradient"] is not None
    page.open_take(live_server, take)
    p = page.page
    box = p.locator("#show-floor")
    assert p.locator("#floor-toggle").is_visible()
    assert box.is_enabled()
    assert box.is_checked()
    assert p.inner_text("#floor-label") == f"floor (tilted {check['tilt_deg']:.1f}°)"
    assert "tilted" in (p.locator("#floor-toggle").get_attribute("class") or "")

    # The plane drawn is the fitted one: each corner on it, and the corners not level.
    floor = p.evaluate("() => window.mocapqaViews.floorDrawn()")
    assert floor["tilted"] is True
    assert floor["axis"] == 1
    corners = np.asarray(floor["corners"], dtype=float).reshape(4, 3)
    np.testing.assert_allclose(corners[:, 1], plane_at(feet, corners), atol=1e-4)
    # The walk's floor drops 0.58 units over its length (docs/feet.md): far from level.
    assert np.ptp(corners[:, 1]) > 0.25
    ARTIFACTS.mkdir(exist_ok=True)
    p.locator("#views").scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "floor-tilted.png"), full_page=False)
    p.click("#camera-side")
    page.settle()
    p.screenshot(path=str(ARTIFACTS / "floor-tilted-side.png"), full_page=False)

    # Keyboard: Tab from the overlay's checkbox reaches the floor's, space turns it off and on.
    p.focus("#overlay")
    p.keyboard.press("Tab")
    assert p.evaluate("() => document.activeElement.id") == "show-floor"
    p.keyboard.press("Space")
    page.settle()
    assert not box.is_checked()
    assert shown(page) == [False, False]
    p.keyboard.press("Space")
    page.settle()
    assert shown(page) == [True, True]
    # Space in the checkbox toggles it and does not start playback.
    assert not p.evaluate("() => window.mocapqaPlayer.playing")
    # The take view's keys still work with the checkbox focused: the right arrow steps a frame.
    before = page.frame()
    p.keyboard.press("ArrowRight")
    page.settle()
    assert page.frame() == before + 1
    assert p.evaluate("() => document.activeElement.id") == "show-floor"

    # Mouse: a click on the checkbox, then on its label's text.
    box.click()
    page.settle()
    assert shown(page) == [False, False]
    p.locator("#floor-label").click()
    page.settle()
    assert box.is_checked()
    assert shown(page) == [True, True]

    # A run without the feet step has no floor: no checkbox.
    other = run_again(live_server, take["id"], {"checks": ["twist"]})
    page.open_take(live_server, {**take, "run": other})
    assert p.evaluate("() => window.mocapqaViews.floorDrawn()") is None
    assert p.locator("#floor-toggle").is_hidden()
    assert box.is_disabled()


def test_a_level_y_down_floor_lies_at_the_feet(
    live_server: str, corpus_dir: Path, page: Page
) -> None:
    take = upload(live_server, corpus_dir / MEDIAPIPE)
    feet = take["result"]["series"]["feet"]
    assert feet["up_axis"] == "-Y"
    assert not feet["floor_check"]["tilted"]
    page.open_take(live_server, take)
    p = page.page
    assert p.inner_text("#floor-label") == "floor"
    assert "tilted" not in (p.locator("#floor-toggle").get_attribute("class") or "")
    floor = p.evaluate("() => window.mocapqaViews.floorDrawn()")
    assert floor["tilted"] is False
    corners = np.asarray(floor["corners"], dtype=float).reshape(4, 3)
    np.testing.assert_allclose(corners[:, 1], feet["floor"], rtol=1e-6)
    # y points down from the hips: the floor lies below the body (larger y than every joint
    # but the feet), within a few cm of the lowest feet.
    frames = httpx.get(
        f"{live_server}/api/v1/runs/{take['run']}/frames", params={"max_frames": 50}, timeout=60
    ).json()
    y = np.asarray(
        [[np.nan] * 3 if q is None else q for f in frames["raw"] for q in f], dtype=float
    )[:, 1]
    assert feet["floor"] > 0.0
    assert abs(feet["floor"] - np.nanmax(y)) < 0.1
