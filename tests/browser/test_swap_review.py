"""Accepting and rejecting the swaps of a C3D marker take in the take view."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.api.test_swap_decisions import SOURCE, SWAPS, exchanged
from tests.browser.test_workstation import Page, upload

from mocapqa.io.c3d import read_c3d, write_c3d

pytestmark = pytest.mark.browser


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def test_swaps_are_accepted_and_rejected_like_intervals(
    live_server: str, corpus_dir: Path, tmp_path: Path, page: Page
) -> None:
    source = corpus_dir / SOURCE
    path = tmp_path / "tennis_serve_swapped.c3d"
    write_c3d(path, exchanged(read_c3d(source), SWAPS), source=source)
    take = upload(live_server, path)
    swaps = [f for f in take["result"]["findings"] if f["kind"] == "swap"]
    assert [(*f["markers"], f["start_frame"], f["end_frame"]) for f in swaps] == list(SWAPS)
    first, second = swaps[0]["id"], swaps[1]["id"]

    p = page.page
    page.open_take(live_server, take)
    p.wait_for_selector("#findings tr[data-interval] td.decision button.decide-accept")
    assert p.locator("#findings tbody tr[data-interval]").count() == 2

    def decision_of(swap: int) -> str:
        return p.inner_text(f"#findings tr[data-interval='{swap}'] td.decision")

    assert decision_of(first).startswith("run: applied")
    assert "undecided" in decision_of(first)
    assert "→ corrected" in decision_of(first)

    # The mouse accepts the first; the keyboard rejects the second (focus its row, press X).
    p.click(f"#findings tr[data-interval='{first}'] button.decide-accept")
    assert "accepted" in decision_of(first)
    p.locator(f"#findings tr[data-interval='{second}']").focus()
    p.keyboard.press("x")
    assert "rejected" in decision_of(second)
    assert "→ left as recorded" in decision_of(second)
    p.wait_for_function("() => document.querySelectorAll('#decision-history li').length === 2")
    latest = p.inner_text("#decision-history").splitlines()[0]
    a, b, start, end = SWAPS[1]
    assert f"{a} ↔ {b} frames {start}–{end}" in latest
    assert "rejected" in latest
    href = p.get_attribute("#download-decided", "href") or ""
    assert href.endswith(f"/runs/{take['run']}/decisions/c3d")

    # Saved: the API has both, and a reload shows them.
    body = httpx.get(f"{live_server}/api/v1/runs/{take['run']}/decisions", timeout=30).json()
    assert {s["id"]: s["decision"] for s in body["swaps"]} == {first: "accept", second: "reject"}
    page.open_take(live_server, take)
    p.wait_for_function(
        "(id) => document.querySelector(`#findings tr[data-interval='${id}'] td.decision`)"
        "?.innerText.includes('rejected')",
        arg=second,
    )
    assert "accepted" in decision_of(first)
    decided = httpx.get(f"{live_server}{href}" if href.startswith("/") else href, timeout=60)
    assert decided.status_code == 200
    assert decided.content[1] == 0x50  # a C3D's parameter-section mark
