"""A slow route says it is loading: the previous page stays until the next one is drawn."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from tests.browser.test_workstation import Page, upload

pytestmark = pytest.mark.browser


@pytest.fixture(scope="module")
def walk(live_server: str, corpus_dir: Path) -> dict[str, Any]:
    return upload(live_server, corpus_dir / "bvh" / "bandai" / "dataset-2_walk_normal_001.bvh")


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium)
    yield opened
    opened.close()


def test_a_slow_take_shows_loading_until_it_is_drawn(
    live_server: str, walk: dict[str, Any], page: Page
) -> None:
    p = page.page
    p.goto(f"{live_server}/#/")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert p.locator("#route-loading").is_hidden()
    # The run's answer is held back (its request parked) until the indicator has been seen.
    held: list[Any] = []

    def park(route: Any) -> None:
        held.append(route)

    p.route(f"**/api/v1/runs/{walk['run']}/result*", park)
    p.evaluate(f"() => {{ location.hash = '#/take/{walk['id']}?run={walk['run']}'; }}")
    p.wait_for_selector("#route-loading", state="visible", timeout=30_000)
    assert p.get_attribute("#main", "aria-busy") == "true"
    # The indicator may show while the view's earlier requests are still out: wait (a bound
    # for a request that never comes, not a speed test) until the result's is parked.
    for _ in range(600):
        if held:
            break
        p.wait_for_timeout(50)
    assert held
    assert p.locator("#route-loading").is_visible()
    for request in held:
        request.continue_()
    p.unroute(f"**/api/v1/runs/{walk['run']}/result*", park)
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    p.wait_for_selector("#route-loading", state="hidden", timeout=30_000)
    assert p.get_attribute("#main", "aria-busy") is None
