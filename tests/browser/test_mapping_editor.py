"""The mapping editor of the take view: a rig whose roles the tables do not find names them by
hand, from the keyboard, with the chosen joint selected on the skeleton, and the re-run uses it."""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.browser.test_workstation import ARTIFACTS, Page, upload

pytestmark = pytest.mark.browser

# The CMU walk with four limb joints renamed to words no role table knows.
RENAMES = {"LeftForeArm": "SegA", "RightForeArm": "SegB", "LeftLeg": "SegC", "RightLeg": "SegD"}
MISSING = ["left_forearm", "left_lower_leg", "right_forearm", "right_lower_leg"]


@pytest.fixture(scope="module")
def odd_rig(live_server: str, corpus_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Any:
    text = (corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh").read_text()
    for old, new in RENAMES.items():
        text = re.sub(rf"\bJOINT {old}\b", f"JOINT {new}", text)
    path = tmp_path_factory.mktemp("rig") / "oddrig.bvh"
    path.write_text(text)
    return upload(live_server, path)


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def test_missing_roles_are_named_by_hand_and_the_rerun_uses_them(
    live_server: str, odd_rig: dict[str, Any], page: Page
) -> None:
    assert sorted(odd_rig["result"]["summary"]["missing_roles"]) == MISSING
    p = page.page
    page.open_take(live_server, odd_rig)
    p.wait_for_selector("#options-roles[open]", timeout=60_000)
    assert all(role in p.inner_text("#roles-missing") for role in MISSING)
    # Automatic roles show the joint found; the missing ones say so.
    assert "automatic (LeftArm)" in p.inner_text("#mapping-left_upper_arm option[value='']")
    assert p.inner_text("#mapping-left_forearm option[value='']") == "automatic (not found)"

    # From the keyboard: focus the role's list and pick the joint by typing its name; the
    # joint is selected on the skeleton as the choice changes.
    for role, joint in (("left_forearm", "SegA"), ("right_forearm", "SegB")):
        p.focus(f"#mapping-{role}")
        p.keyboard.type(joint)
        assert p.input_value(f"#mapping-{role}") == joint
        page.settle()
        assert f"selected: {joint}" in p.inner_text("#joint-label")
    p.locator("#options-roles").scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "mapping-editor.png"))

    p.click("#rerun")
    p.wait_for_url(re.compile(r".*run=(?!" + odd_rig["run"] + r").*"), timeout=60_000)
    run_id = re.search(r"run=([0-9a-f]+)", p.url).group(1)  # type: ignore[union-attr]
    deadline = time.monotonic() + 120
    while (run := httpx.get(f"{live_server}/api/v1/runs/{run_id}").json())["status"] not in (
        "done",
        "failed",
    ):
        assert time.monotonic() < deadline, run
        time.sleep(0.3)
    assert run["options"]["mapping"] == {"left_forearm": "SegA", "right_forearm": "SegB"}
    summary = httpx.get(f"{live_server}/api/v1/runs/{run_id}/result").json()["summary"]
    assert sorted(summary["missing_roles"]) == ["left_lower_leg", "right_lower_leg"]
    assert summary["roles"]["left_forearm"] == "SegA"


def test_a_rig_no_check_could_read_says_so_above_its_findings(
    live_server: str, corpus_dir: Path, page: Page, tmp_path: Path
) -> None:
    """Every joint renamed to a number: nothing was checked, and the take view says so at the
    top, pointing at the mapping editor, instead of an innocent "No findings"."""
    text = (corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh").read_text()
    names = re.findall(r"\b(?:ROOT|JOINT) (\S+)", text)
    for k, name in enumerate(names):
        text = re.sub(rf"\b(ROOT|JOINT) {re.escape(name)}\b", rf"\g<1> j{k}", text)
    path = tmp_path / "anonymous.bvh"
    path.write_text(text)
    take = upload(live_server, path)
    assert take["result"]["steps"]["twist"]["state"] == "no_roles"
    page.open_take(live_server, take)
    note = page.page.inner_text("#not-checked")
    assert note.startswith("Not checked:")
    assert "no limb chain found" in note
    assert "Rig roles (mapping)" in note
