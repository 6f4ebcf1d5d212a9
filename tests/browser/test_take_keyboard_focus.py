"""The take view's keys and focus, driven as a keyboard user drives them, on 005_05.

The view's keys after a drag of the scrubber; the findings row reached by N/P or focused by Tab
shown below the pinned player bar (1280, 900 and 700 px wide); the run pickers (the take's, and
Compare's A and B) keeping the focus through the redraw their choice starts; the view options
and the frame shown during playback kept through a reload; the selected joint's whole name.
Screenshots go to ``tests/artifacts/`` (gitignored): ``focus-row-below-player-<width>.png``.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from tests.browser.test_workstation import ARTIFACTS, KNEES_TAKE, Page, run_again, upload

pytestmark = pytest.mark.browser

FRAME_IN_LINK = "() => Number(new URLSearchParams(location.hash.split('?')[1]).get('frame'))"
# The focused element's box and the player bar's, in the window's coordinates; null when the
# focus is not on the page's part under the bar (the findings, the review, …).
BELOW_PLAYER = """() => {
  const player = document.getElementById('player');
  const el = document.activeElement;
  const after = el && (player.compareDocumentPosition(el) & Node.DOCUMENT_POSITION_FOLLOWING);
  if (!after || player.contains(el)) return null;
  const r = el.getBoundingClientRect(), p = player.getBoundingClientRect();
  return { top: r.top, bottom: r.bottom, playerBottom: p.bottom, height: innerHeight,
    tag: el.tagName };
}"""
CURRENT_ROW = """() => {
  const r = document.querySelector('#findings tr.finding.current').getBoundingClientRect();
  const p = document.getElementById('player').getBoundingClientRect();
  return { top: r.top, bottom: r.bottom, playerBottom: p.bottom, height: innerHeight };
}"""


@pytest.fixture(scope="module")
def knees(live_server: str, corpus_dir: Path) -> dict[str, Any]:
    """The take with two runs: the first (every check) and a twist-only one."""
    take = upload(live_server, corpus_dir / KNEES_TAKE)
    take["second"] = run_again(live_server, take["id"], {"checks": ["twist"]})
    return take


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium, width=1280, height=900)
    yield opened
    opened.close()


def mark_old(page: Page, selector: str) -> None:
    """Mark the element drawn now, to tell it from the one a redraw puts in its place."""
    page.page.eval_on_selector(selector, "e => { e.dataset.old = '1'; }")


def focused_anew(page: Page, element_id: str) -> None:
    """Wait until the focus is on a new element of that id (drawn again, not the marked one)."""
    page.page.wait_for_function(
        "(id) => { const e = document.activeElement;"
        " return e && e.id === id && !e.dataset.old && e.isConnected; }",
        arg=element_id,
        timeout=60_000,
    )


def tab_to(page: Page, element_id: str, presses: int = 60) -> None:
    """Press Tab from the page's start until `element_id` has the focus."""
    p = page.page
    p.evaluate("() => { document.activeElement.blur(); window.scrollTo(0, 0); }")
    for _ in range(presses):
        p.keyboard.press("Tab")
        if p.evaluate("(id) => document.activeElement.id === id", element_id):
            return
    raise AssertionError(f"Tab never reached #{element_id}")


def test_view_keys_work_after_dragging_the_scrubber(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees)
    box = p.locator("#scrubber").bounding_box()
    y = box["y"] + box["height"] / 2
    p.mouse.move(box["x"] + box["width"] * 0.2, y)
    p.mouse.down()
    for step in range(1, 11):
        p.mouse.move(box["x"] + box["width"] * (0.2 + 0.02 * step), y)
    p.mouse.up()
    assert p.evaluate("() => document.activeElement.id") == "scrubber"
    dragged = page.frame()
    assert dragged > 0
    # Space plays and pauses with the scrubber focused.
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('pause')")
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('play')")
    assert p.evaluate("() => document.activeElement.id") == "scrubber"
    # I marks the in point; N opens the next finding (its row marked, its first frame shown).
    at = page.frame()
    p.keyboard.press("i")
    p.wait_for_function(
        "(f) => document.getElementById('loop-label').textContent.startsWith(`in ${f} `)", arg=at
    )
    starts = sorted({f["start_frame"] for f in knees["result"]["findings"]})
    reached = next(s for s in starts if s > at)
    p.keyboard.press("n")
    p.wait_for_selector("#findings tr.finding.current")
    assert page.frame() == reached
    # The slider keeps its own keys: the arrows move it one frame, End to the last.
    p.focus("#scrubber")
    p.keyboard.press("ArrowRight")
    p.wait_for_function(
        "(f) => document.getElementById('frame-label').textContent.startsWith(`frame ${f} `)",
        arg=reached + 1,
    )
    p.keyboard.press("End")
    last = int(p.get_attribute("#scrubber", "max"))
    p.wait_for_function(
        "(f) => document.getElementById('frame-label').textContent.startsWith(`frame ${f} `)",
        arg=last,
    )
    # A text field still takes its letters as text.
    p.focus("#filter-text")
    p.keyboard.type("np")
    assert p.input_value("#filter-text") == "np"
    assert page.frame() == last


def check_below(box: dict[str, float] | None, what: str) -> None:
    assert box is not None, what
    assert box["top"] >= box["playerBottom"] - 1, (what, box)
    assert box["bottom"] <= box["height"] + 1, (what, box)


@pytest.mark.parametrize("width", [1280, 900, 700])
def test_walked_and_tabbed_rows_show_below_the_player(
    live_server: str, knees: dict[str, Any], chromium: Any, width: int
) -> None:
    page = Page(chromium, width=width, height=900)
    p = page.page
    page.open_take(live_server, knees)
    assert p.evaluate("() => getComputedStyle(document.getElementById('player')).position") == (
        "sticky"
    )
    p.locator("h1").first.click()
    # N down the findings, then P back up: each row reached is below the bar, in the window.
    for key in ["n"] * 8 + ["p"] * 6:
        p.evaluate(
            "() => document.querySelectorAll('#findings tr.finding').forEach((r) =>"
            " { r.dataset.was = r.classList.contains('current') ? '1' : ''; })"
        )
        p.keyboard.press(key)
        p.wait_for_function(
            "() => { const c = document.querySelector('#findings tr.finding.current');"
            " return c && c.dataset.was !== '1'; }"
        )
        check_below(p.evaluate(CURRENT_ROW), f"{key} at {page.frame()}")
    ARTIFACTS.mkdir(exist_ok=True)
    p.screenshot(path=str(ARTIFACTS / f"focus-row-below-player-{width}.png"))
    # Tab from the last row back up the list (rows, their buttons): each stop below the bar.
    p.locator("#findings tr.finding").last.focus()
    for _ in range(40):
        p.keyboard.press("Shift+Tab")
        box = p.evaluate(BELOW_PLAYER)
        if box is None:
            break
        check_below(box, f"Shift+Tab to a {box['tag']}")
    # And forward again from the first row.
    p.locator("#findings tr.finding").first.focus()
    for _ in range(20):
        p.keyboard.press("Tab")
        box = p.evaluate(BELOW_PLAYER)
        check_below(box, "Tab")
    page.close()


def test_the_run_pickers_keep_the_focus_through_the_redraw(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees)
    tab_to(page, "run-pick")
    mark_old(page, "#run-pick")
    p.keyboard.press("ArrowDown")  # the first run is chosen; the second is next
    focused_anew(page, "run-pick")
    assert f"run={knees['second']}" in p.evaluate("() => location.hash")
    assert p.input_value("#run-pick") == knees["second"]
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert p.evaluate("() => document.activeElement.id") == "run-pick"
    # The keyboard goes on choosing: back to the first run, the focus back again.
    mark_old(page, "#run-pick")
    p.keyboard.press("ArrowUp")
    focused_anew(page, "run-pick")
    assert p.input_value("#run-pick") == knees["run"]
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    page.settle()
    # Compare's pickers: B chosen by the keyboard keeps the focus, then A.
    p.goto(f"{live_server}/#/compare?a={knees['run']}")
    p.wait_for_selector("#compare-table")
    tab_to(page, "compare-b")
    mark_old(page, "#compare-b")
    p.keyboard.press("ArrowDown")
    focused_anew(page, "compare-b")
    assert p.input_value("#compare-b") != ""
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert p.evaluate("() => document.activeElement.id") == "compare-b"
    p.keyboard.press("Shift+Tab")
    assert p.evaluate("() => document.activeElement.id") == "compare-a"
    mark_old(page, "#compare-a")
    p.keyboard.press("ArrowDown")
    focused_anew(page, "compare-a")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)


def test_view_options_survive_a_reload(live_server: str, knees: dict[str, Any], page: Page) -> None:
    p = page.page
    page.open_take(live_server, knees)
    assert p.locator("#floor-toggle").is_visible()
    assert p.is_checked("#show-floor")
    assert not p.is_checked("#show-axes")
    assert not p.is_checked("#overlay")
    for box in ("#show-axes", "#overlay", "#show-floor"):
        p.focus(box)
        p.keyboard.press("Space")
    p.wait_for_function(
        "() => { const q = new URLSearchParams(location.hash.split('?')[1]);"
        " return q.get('axes') === '1' && q.get('overlay') === '1' && q.get('floor') === '0'; }"
    )
    p.reload()
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    page.settle()
    assert p.is_checked("#show-axes")
    assert p.is_checked("#overlay")
    assert not p.is_checked("#show-floor")
    assert p.locator("#panel-raw").is_hidden()  # the overlay draws raw as a ghost instead
    assert p.evaluate("() => window.mocapqaViews.floorDrawn().shown") == [False, False]
    # Unticked again, the link forgets them and a reload shows the defaults.
    for box in ("#show-axes", "#overlay", "#show-floor"):
        p.click(box)
    p.wait_for_function(
        "() => !/[?&](axes|overlay|floor)=/.test(location.hash)",
    )
    p.reload()
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert not p.is_checked("#show-axes")
    assert not p.is_checked("#overlay")
    assert p.is_checked("#show-floor")
    assert p.locator("#panel-raw").is_visible()


def test_a_reload_during_playback_opens_near_the_frame_shown(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees, frame=0)
    entries = p.evaluate("() => history.length")
    p.locator("h1").first.click()
    p.keyboard.press("Space")
    p.wait_for_function("() => document.getElementById('play').textContent.endsWith('pause')")
    # The link follows playback (a few times a second), replacing the address.
    p.wait_for_function(f"() => ({FRAME_IN_LINK})() >= 20", timeout=60_000)
    p.wait_for_function(f"() => ({FRAME_IN_LINK})() >= 40", timeout=60_000)
    assert p.evaluate("() => history.length") == entries
    assert p.evaluate("() => document.getElementById('play').textContent.endsWith('pause')")
    linked = p.evaluate(FRAME_IN_LINK)
    p.reload()
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert page.frame() >= linked >= 40


def test_the_selected_joints_whole_name_at_700_px(
    live_server: str, knees: dict[str, Any], chromium: Any
) -> None:
    page = Page(chromium, width=700, height=900)
    p = page.page
    page.open_take(live_server, knees)
    p.locator("h1").first.click()
    p.keyboard.press("n")
    p.wait_for_selector("#findings tr.finding.current")
    joint = p.get_attribute("#findings tr.finding.current", "data-joint")
    label = p.locator("#joint-label")
    assert label.inner_text() == f"selected: {joint}"
    assert label.get_attribute("title") == f"selected: {joint}"
    # On a line of its own, the name is not cut.
    assert p.eval_on_selector("#joint-label", "e => e.scrollWidth <= e.clientWidth")
    page.close()
