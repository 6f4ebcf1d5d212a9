"""Accepting and rejecting a foot lock in the take view, on a real BVH walk with a slide
injected into one contact (tests/api/test_feet_decisions.py): the reviewed download locks the
accepted foot and leaves everything above the hips as it was."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import numpy as np
import pytest
from tests.api.test_feet_decisions import injected_skate, leg_joints, write_slid_walk
from tests.browser.test_workstation import ARTIFACTS, Page, upload

from mocapqa.core.rig import find_roles
from mocapqa.io.bvh import parse_bvh
from mocapqa.kinematics.forward import forward_kinematics

pytestmark = pytest.mark.browser


def download_text(kept: int, n: int) -> str:
    """The reviewed download's link text with ``kept`` of ``n`` foot locks applied."""
    return f"Download reviewed take ({kept} of {n} foot lock{'s' if n > 1 else ''} applied)"


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def cell(page: Page, lock: str) -> str:
    return page.page.inner_text(f"#findings tr[data-lock='{lock}'] td.decision")


def timeline_lock(page: Page, lock: str) -> dict[str, str]:
    """The contact timeline's mark of a foot lock: its decision and drawn background."""
    mark = page.page.locator(f"#contact-timeline .ct-lock[data-lock='{lock}']")
    background: str = mark.evaluate(
        "(el) => getComputedStyle(el).backgroundImage + ' ' + getComputedStyle(el).backgroundColor"
    )
    return {"decision": mark.get_attribute("data-decision") or "", "background": background}


def decided(server: str, run_id: str) -> bytes:
    response = httpx.get(f"{server}/api/v1/runs/{run_id}/decisions/bvh", timeout=120)
    response.raise_for_status()
    return response.content


def test_accepting_a_foot_lock_changes_the_foot_and_nothing_above_the_hips(
    live_server: str, corpus_dir: Path, tmp_path: Path, page: Page
) -> None:
    path, foot, start, end = write_slid_walk(corpus_dir, tmp_path)
    take = upload(live_server, path)
    skates = [f for f in take["result"]["findings"] if f["kind"] == "skate"]
    skate = injected_skate(take["result"], foot, start, end)
    lock, n = skate["id"], len(skates)
    run_id = take["run"]
    p = page.page
    page.open_take(live_server, take)
    p.wait_for_selector(f"#findings tr[data-lock='{lock}'] button.decide-accept")
    assert p.locator("#findings tr[data-lock]").count() == n
    # Undecided: cleanup is off, the run locks nothing and the download applies no lock.
    assert cell(page, lock).startswith("run: cleanup off")
    assert "undecided" in cell(page, lock)
    assert "→ left as recorded" in cell(page, lock)
    link = p.locator("#download-decided")
    assert link.inner_text() == download_text(0, n)
    before = decided(live_server, run_id)
    # The contact timeline draws each lock, undecided as an outline, over the contact the skate
    # overlaps.
    assert p.locator("#contact-timeline .ct-lock").count() == n
    undecided = timeline_lock(page, lock)
    assert undecided["decision"] == "undecided"
    mark = p.locator(f"#contact-timeline .ct-lock[data-lock='{lock}']")
    assert int(mark.get_attribute("data-start") or -1) <= skate["end_frame"]
    assert int(mark.get_attribute("data-end") or -1) >= skate["start_frame"]

    p.click(f"#findings tr[data-lock='{lock}'] button.decide-accept")
    assert "accepted" in cell(page, lock)
    assert "→ locked" in cell(page, lock)
    # The timeline's mark follows the decision at once: filled.
    p.wait_for_selector(f"#contact-timeline .ct-lock[data-lock='{lock}'][data-decision='accept']")
    accepted = timeline_lock(page, lock)
    assert accepted["background"] != undecided["background"]
    assert "accepted" in (mark.get_attribute("title") or "")
    p.locator("#contact-timeline").scroll_into_view_if_needed()
    ARTIFACTS.mkdir(exist_ok=True)
    p.locator("#contact-timeline").screenshot(path=str(ARTIFACTS / "feet-lock-timeline.png"))
    p.wait_for_function("() => document.getElementById('download-decided').dataset.locks === '1'")
    assert link.inner_text() == download_text(1, n)
    p.wait_for_selector("#decision-history li")
    latest = p.inner_text("#decision-history").splitlines()[0]
    assert f"{foot} foot lock frames {skate['start_frame']}–{skate['end_frame']}" in latest
    p.locator(f"#findings tr[data-lock='{lock}']").scroll_into_view_if_needed()
    ARTIFACTS.mkdir(exist_ok=True)
    p.locator("#findings").locator("xpath=..").screenshot(
        path=str(ARTIFACTS / "feet-lock-accepted.png")
    )

    # The link serves the API's decided take: the foot held, the upper body untouched.
    with p.expect_download() as download:
        p.click("#download-decided")
    served = Path(download.value.path()).read_bytes()
    assert served == decided(live_server, run_id)
    assert served != before
    old, new = parse_bvh(before.decode(), "before.bvh"), parse_bvh(served.decode(), "after.bvh")
    legs = leg_joints(path)
    upper = [j for j in range(new.skeleton.n_joints) if j not in legs]
    old_quats, old_positions = forward_kinematics(old)
    new_quats, new_positions = forward_kinematics(new)
    np.testing.assert_array_equal(new_positions[:, upper], old_positions[:, upper])
    np.testing.assert_array_equal(new_quats[:, upper], old_quats[:, upper])
    ankle = find_roles(new.skeleton).joint(foot, "foot")
    assert ankle is not None
    assert np.abs(new_positions[:, ankle] - old_positions[:, ankle]).max() > 1e-3

    # Undo from the keyboard: focus the lock's row, press X; the download is the one before.
    p.locator(f"#findings tr[data-lock='{lock}']").focus()
    p.keyboard.press("x")
    assert "rejected" in cell(page, lock)
    rejected = timeline_lock(page, lock)
    assert rejected["decision"] == "reject"
    assert "repeating-linear-gradient" in rejected["background"]
    assert len({rejected["background"], accepted["background"], undecided["background"]}) == 3
    p.wait_for_function("() => document.querySelectorAll('#decision-history li').length === 2")
    assert link.inner_text() == download_text(0, n)
    assert decided(live_server, run_id) == before
    # After a reload the newest decision is still there (it comes from the server).
    page.open_take(live_server, take)
    p.wait_for_selector("#decision-history li")
    assert "rejected" in cell(page, lock)
    p.wait_for_selector(f"#contact-timeline .ct-lock[data-lock='{lock}'][data-decision='reject']")
    assert not page.errors, page.errors


def test_a_run_that_locks_the_skates_is_chosen_in_the_form_and_reviewed_lock_by_lock(
    live_server: str, corpus_dir: Path, tmp_path: Path, page: Page
) -> None:
    path, foot, start, end = write_slid_walk(corpus_dir, tmp_path)
    take = upload(live_server, path)
    skate = injected_skate(take["result"], foot, start, end)
    lock = skate["id"]
    n = sum(f["kind"] == "skate" for f in take["result"]["findings"])
    p = page.page
    # A run naming a lock the take does not have fails, saying why; the page still offers the
    # take's other runs.
    bad = httpx.post(
        f"{live_server}/api/v1/takes/{take['id']}/runs",
        json={"checks": ["feet"], "feet_apply": "skate-left-99999"},
        timeout=30,
    ).json()
    page.open_take(live_server, take)
    p.evaluate("(hash) => { location.hash = hash; }", f"#/take/{take['id']}?run={bad['id']}")
    p.wait_for_selector("main p.error", timeout=120_000)
    assert "feet_apply ids of skate findings" in p.inner_text("main p.error")
    p.select_option("#run-pick", take["run"])
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    page.settle()
    # The re-run form offers the cleanup in the feet group, off by default; chosen by keyboard.
    field = p.locator("#option-feet_apply")
    field.scroll_into_view_if_needed()
    assert p.input_value("#option-feet_apply") == "none"
    assert field.locator("xpath=ancestor::fieldset").get_attribute("data-group") == "feet"
    field.focus()
    p.keyboard.type("skates")
    assert p.input_value("#option-feet_apply") == "skates"
    p.click("#rerun")
    p.wait_for_url(re.compile(r".*run=(?!" + take["run"] + r").*"), timeout=60_000)
    run_id = re.search(r"run=([0-9a-f]+)", p.url).group(1)  # type: ignore[union-attr]
    run = httpx.get(f"{live_server}/api/v1/runs/{run_id}", timeout=30).json()
    assert run["options"]["feet_apply"] == "skates"
    # The new run's view replaces the old one's rows (the same lock ids) once the run is done.
    p.wait_for_function(
        "(run) => document.querySelector('#run-pick')?.value === run"
        " && document.querySelector('main')?.dataset.ready === '1'",
        arg=run_id,
        timeout=120_000,
    )
    p.wait_for_selector(f"#findings tr[data-lock='{lock}'] button.decide-accept", timeout=120_000)
    # Undecided, each lock follows the run: locked in its corrected take and the reviewed one.
    assert cell(page, lock).startswith("run: locked")
    assert "undecided" in cell(page, lock)
    assert "→ locked" in cell(page, lock)
    link = p.locator("#download-decided")
    assert link.inner_text() == download_text(n, n)
    mark = p.locator(f"#contact-timeline .ct-lock[data-lock='{lock}']")
    assert "locked in the run's corrected take" in (mark.get_attribute("title") or "")
    assert "linear-gradient" in timeline_lock(page, lock)["background"]
    assert "feet locked skates" in p.inner_text("#run-pick")
    p.locator("#contact-timeline").scroll_into_view_if_needed()
    ARTIFACTS.mkdir(exist_ok=True)
    p.screenshot(path=str(ARTIFACTS / "feet-locks-run.png"))
    # Rejecting one undoes it in the reviewed take only.
    p.click(f"#findings tr[data-lock='{lock}'] button.decide-reject")
    assert "→ left as recorded" in cell(page, lock)
    p.wait_for_function(
        "(n) => document.getElementById('download-decided').dataset.locks === String(n)",
        arg=n - 1,
    )
    body = httpx.get(f"{live_server}/api/v1/runs/{run_id}/decisions", timeout=30).json()
    assert {x["id"]: x["applied"] for x in body["locks"]}[lock] is False
    assert all(x["applied"] for x in body["locks"] if x["id"] != lock)
    assert not page.errors, page.errors
