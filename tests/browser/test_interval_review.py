"""Accepting and rejecting twist intervals in the take view, on 005_05's real knee errors."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.browser.test_workstation import ARTIFACTS, KNEES_TAKE, Page, scrub, upload

pytestmark = pytest.mark.browser


@pytest.fixture(scope="module")
def knees(live_server: str, corpus_dir: Path) -> dict[str, Any]:
    return upload(live_server, corpus_dir / KNEES_TAKE)


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def decision_of(page: Page, interval: int) -> str:
    return page.page.inner_text(f"#findings tr[data-interval='{interval}'] td.decision")


def test_accept_and_reject_intervals_persist_and_the_download_has_them(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees)
    rows = p.locator("#findings tbody tr[data-interval]")
    p.wait_for_selector("#findings td.decision button.decide-accept")
    assert rows.count() >= 2
    twist = {f["id"]: f for f in knees["result"]["findings"] if f["kind"] == "twist"}
    # Accept one the run left alone and reject one it applied: both change the corrected take.
    first = next((i for i, f in twist.items() if not f["applied"]), min(twist))
    second = next(i for i, f in twist.items() if f["applied"] and i != first)
    # Each twist row shows its confidence in %, whether the run applied it, and no decision yet.
    cells = p.locator(f"#findings tr[data-interval='{first}'] td")
    assert cells.nth(5).inner_text() == f"{round(100 * twist[first]['confidence'])} %"
    applied = "run: not applied" if not twist[first]["applied"] else "run: applied"
    assert decision_of(page, first).startswith(applied)
    assert "undecided" in decision_of(page, first)
    # ... and what the reviewed download will do with it: the run's choice until decided.
    outcome = "→ corrected" if twist[first]["applied"] else "→ left as recorded"
    assert outcome in decision_of(page, first)

    # The mouse accepts the first; the decision shows before the server has answered.
    p.click(f"#findings tr[data-interval='{first}'] button.decide-accept")
    assert "accepted" in decision_of(page, first)
    assert "→ corrected" in decision_of(page, first)
    # The keyboard rejects the second: focus its row, press X.
    p.locator(f"#findings tr[data-interval='{second}']").focus()
    p.keyboard.press("x")
    assert "rejected" in decision_of(page, second)
    assert "→ left as recorded" in decision_of(page, second)
    p.wait_for_function("() => document.querySelectorAll('#decision-history li').length === 2")
    history = p.inner_text("#decision-history")
    # Named as its findings row shows it (joint and frames), not by the internal id.
    shown = twist[second]
    assert (
        f"{shown['joint']} frames {shown['start_frame']}–{shown['end_frame']}"
        in history.splitlines()[0]
    )
    assert f"interval {second}" not in history
    assert "rejected" in history.splitlines()[0]
    p.locator("#findings").scroll_into_view_if_needed()
    ARTIFACTS.mkdir(exist_ok=True)
    p.locator("#findings").locator("xpath=..").screenshot(
        path=str(ARTIFACTS / "decisions-accept-reject.png")
    )
    # In a narrow window the read-outs (accepted, rejected, undecided) wrap, but each row's
    # Accept and Reject stay side by side, equally wide, in line with every other row's.
    p.set_viewport_size({"width": 800, "height": 1000})
    boxes = p.evaluate(
        "() => [...document.querySelectorAll('#findings tr[data-interval] td.decision')].map((c) =>"
        " ['accept', 'reject'].map((d) => { const b = c.querySelector(`button.decide-${d}`)"
        ".getBoundingClientRect(); return [b.left, b.top, b.width, b.height]; }))"
    )
    assert len(boxes) >= 2
    for k in (0, 1):  # the Accepts line up, and the Rejects
        lefts = [row[k][0] for row in boxes]
        assert max(lefts) - min(lefts) < 1
    for accept, reject in boxes:
        assert accept[2] == pytest.approx(reject[2], abs=0.5)  # equally wide
        assert accept[1] == pytest.approx(reject[1], abs=0.5)  # on one line
        assert accept[0] + accept[2] <= reject[0]
    # ... and the table fits the window (the canvas and charts follow the resize a frame later).
    assert p.evaluate(
        "() => document.getElementById('findings').getBoundingClientRect().right <= innerWidth"
    )
    p.locator("#findings").locator("xpath=..").screenshot(
        path=str(ARTIFACTS / "decisions-accept-reject-800px.png")
    )
    p.set_viewport_size({"width": 1400, "height": 1000})

    # After a reload the decisions are still there (they come from the server).
    page.open_take(live_server, knees)
    p.wait_for_selector("#decision-history li")
    assert "accepted" in decision_of(page, first)
    assert "rejected" in decision_of(page, second)
    assert p.locator("#decision-history li").count() == 2

    # The link serves the BVH with exactly these decisions (the API's decided take).
    with p.expect_download() as download:
        p.click("#download-decided")
    served = Path(download.value.path()).read_bytes()
    assert served.startswith(b"HIERARCHY")
    expected = httpx.get(f"{live_server}/api/v1/runs/{knees['run']}/decisions/bvh", timeout=60)
    assert served == expected.content
    corrected = httpx.get(f"{live_server}/api/v1/runs/{knees['run']}/download/bvh", timeout=60)
    assert served != corrected.content  # the decisions changed the run's own choice
    # A decision made from the keyboard keeps the focus on its button (it was redrawn away).
    p.focus(f"#findings tr[data-interval='{second}'] button.decide-accept")
    p.keyboard.press("Enter")
    p.wait_for_function(
        "(id) => document.activeElement?.matches(`tr[data-interval='${id}'] button.decide-accept`)",
        arg=second,
    )


def test_limb_spins_are_listed_with_their_read_out_and_nothing_to_accept(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    """005_05's right leg flips and right arm spins show as findings of their own kind, with
    a sentence saying they were not corrected, and no accept/reject buttons; the kind filter
    hides them."""
    p = page.page
    page.open_take(live_server, knees)
    spins = [f for f in knees["result"]["findings"] if f["kind"] == "spin"]
    assert any(f["shape"] == "flip" for f in spins)
    assert any(f["shape"] == "spin" for f in spins)
    rows = p.locator("#findings tbody tr", has=p.locator("td:first-child", has_text="spin"))
    assert rows.count() == len(spins)
    first = rows.first.inner_text()
    assert "about its axis" in first
    assert "not corrected" in first
    assert rows.first.locator("button").count() == 0
    p.uncheck("#filter-kind-spin")
    assert rows.count() == 0
    p.check("#filter-kind-spin")
    assert rows.count() == len(spins)

    # Y on a focused spin row decides nothing, not even the twist interval opened before it.
    p.wait_for_selector("#findings td.decision button.decide-accept")
    history = p.locator("#decision-history li")
    before = history.count()
    p.locator("#findings tr[data-interval]").first.click()
    rows.first.focus()
    p.keyboard.press("y")
    assert "not corrected" in p.inner_text("#decision-message")
    p.wait_for_timeout(300)  # a decision would be posted and listed by now
    assert history.count() == before


def test_n_then_y_decides_the_twist_interval_reached_and_says_so_on_screen(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    """A spin row clicked (and so focused), then N walks on to a twist interval: Y accepts the
    interval reached, not the focused spin row, and the answer shows in a toast."""
    p = page.page
    page.open_take(live_server, knees)
    p.wait_for_selector("#findings td.decision button.decide-accept")
    spin = p.locator("#findings tr.finding[data-kind='spin']").first
    spin.click()
    reached = None
    for _ in range(60):
        p.keyboard.press("n")
        current = p.locator("#findings tr.finding.current")
        if current.count() and current.get_attribute("data-kind") == "twist":
            reached = current.get_attribute("data-interval")
            break
    assert reached is not None
    p.keyboard.press("y")
    p.wait_for_function(
        "(id) => document.querySelector(`#findings tr[data-interval='${id}'] td.decision`)"
        "?.innerText.includes('accepted')",
        arg=reached,
    )
    # Once the server has saved it, the answer shows at the bottom of the window.
    p.wait_for_function(
        "() => { const t = document.getElementById('toast');"
        " return t && !t.hidden && t.textContent.includes('accepted'); }"
    )


def test_a_re_run_says_which_run_holds_the_decisions(
    live_server: str, corpus_dir: Path, page: Page
) -> None:
    """Decisions belong to the run they were made on: the take's re-run starts undecided and
    says so, with a link back to the decided run."""
    import time

    take = upload(live_server, corpus_dir / KNEES_TAKE)
    twist = next(f for f in take["result"]["findings"] if f["kind"] == "twist")
    decided = httpx.post(
        f"{live_server}/api/v1/runs/{take['run']}/intervals/{twist['id']}/decisions",
        json={"decision": "reject"},
        timeout=30,
    )
    assert decided.status_code == 201, decided.text
    rerun = httpx.post(
        f"{live_server}/api/v1/takes/{take['id']}/runs", json={"twist_apply": "all"}, timeout=30
    ).json()
    deadline = time.monotonic() + 300
    while (
        httpx.get(f"{live_server}/api/v1/runs/{rerun['id']}", timeout=30).json()["status"] != "done"
    ):
        assert time.monotonic() < deadline, "the re-run did not finish"
        time.sleep(0.3)
    page.open_take(live_server, {"id": take["id"], "run": rerun["id"]})
    p = page.page
    p.wait_for_selector("#decisions-elsewhere:not([hidden])", timeout=30_000)
    notice = p.inner_text("#decisions-elsewhere")
    assert "Run 1 holds 1 decision" in notice
    assert "this run has none yet" in notice
    # Another run opens at the frame shown, not at frame 0.
    scrub(page, 120)
    p.select_option("#run-pick", take["run"])
    p.wait_for_function(f"() => location.hash.includes('run={take['run']}&frame=120')")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert page.frame() == 120
    page.open_take(live_server, {"id": take["id"], "run": rerun["id"]})
    p.wait_for_selector("#decisions-elsewhere:not([hidden])", timeout=30_000)
    p.click("#decisions-elsewhere-link")
    p.wait_for_function(f"() => location.hash.includes('run={take['run']}')")
    p.wait_for_selector("main[data-ready='1'] #decision-history li", timeout=60_000)
    assert p.locator("#decisions-elsewhere:not([hidden])").count() == 0
