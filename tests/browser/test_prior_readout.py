"""The take view says why a shoot's reviewers moved a twist interval's confidence."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.browser.test_workstation import ARTIFACTS, KNEES_TAKE, Page, wait_for_run

pytestmark = pytest.mark.browser


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def import_take(server: str, shoot: str, name: str, data: bytes) -> dict[str, Any]:
    """Import ``data`` into the shoot as ``name`` and wait for its first run; its twist
    findings under ``"twist"``."""
    response = httpx.post(
        f"{server}/api/v1/shoots/{shoot}/takes", files=[("files", (name, data))], timeout=120
    )
    response.raise_for_status()
    created = response.json()["created"][0]
    wait_for_run(server, created["run_id"], name)
    result = httpx.get(f"{server}/api/v1/runs/{created['run_id']}/result", timeout=30).json()
    twist = [f for f in result["findings"] if f["kind"] == "twist"]
    return {"id": created["take_id"], "run": created["run_id"], "twist": twist}


def test_the_findings_row_says_how_the_shoots_decisions_moved_its_confidence(
    live_server: str, corpus_dir: Path, page: Page
) -> None:
    data = (corpus_dir / KNEES_TAKE).read_bytes()
    shoot = httpx.post(f"{live_server}/api/v1/shoots", json={"name": "knees"}, timeout=30)
    shoot.raise_for_status()
    sid = shoot.json()["id"]
    first = import_take(live_server, sid, "first.bvh", data)
    # An interval the default leaves, on a joint the reviewers then accept on three takes.
    left = next(
        f for f in first["twist"] if not f["applied"] and "calibrated probability" in f["readout"]
    )
    joint = left["joint"]
    for take in (first, import_take(live_server, sid, "second.bvh", data),
                 import_take(live_server, sid, "fourth.bvh", data)):  # fmt: skip
        for finding in take["twist"]:
            if finding["joint"] == joint:
                decided = httpx.post(
                    f"{live_server}/api/v1/runs/{take['run']}/intervals/{finding['id']}/decisions",
                    json={"decision": "accept"},
                    timeout=30,
                )
                assert decided.status_code == 201, decided.text
    third = import_take(live_server, sid, "third.bvh", data)
    moved = next(f for f in third["twist"] if f["id"] == left["id"])
    assert moved["applied"]

    page.open_take(live_server, third)
    p = page.page
    row = p.locator(f"#findings tr.finding[data-interval='{left['id']}']")
    row.scroll_into_view_if_needed()
    readout = row.locator(".readout").inner_text()
    assert "accepted intervals on this joint in this shoot" in readout, readout
    assert "which changed the default" in readout
    # The confidence column shows both probabilities: the calibrated one and the one the
    # decision used, in one notation.
    confidence = row.locator("td.confidence").inner_text()
    before = round(100 * moved["confidence"])
    assert confidence.startswith(f"{before} % →"), confidence
    assert "run: applied" in row.inner_text()
    ARTIFACTS.mkdir(exist_ok=True)
    row.screenshot(path=str(ARTIFACTS / "twist-prior-readout.png"))
