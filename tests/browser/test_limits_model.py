"""Choosing a shoot's joint-limits model in Debian's Chromium: a viewer sees the model's name,
an admin picks another from the models the server offers (a registered one here), sees that
the take's latest run used the old one and runs it again with the new one from the panel."""

from __future__ import annotations

import time
from collections.abc import Iterator
from datetime import timedelta
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.browser.test_shoot_manage import PASSWORD, open_shoot, sign_in
from tests.live_server import serve

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.limits.catalog import ModelCatalog
from mocapqa.limits.storage import default_model_paths
from mocapqa.store.accounts import Accounts
from mocapqa.store.roles import Role

pytestmark = pytest.mark.browser

ARTIFACTS = Path(__file__).resolve().parents[1] / "artifacts"
RUN_BOUND_S = 900.0
"""Generous bound on one run of the CMU walk (a hang fails, a loaded machine does not)."""


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory, cmu_walk: Path) -> Iterator[dict[str, Any]]:
    """A server with an admin ``ada`` and a viewer ``vic``, a model registered as ``walks``
    (a copy of the shipped CMU model) and a shoot holding the CMU walk."""
    settings = Settings(data_dir=tmp_path_factory.mktemp("limits-model"))
    app = create_app(settings)
    with serve(app) as url:
        accounts: Accounts = app.state.accounts
        ada = accounts.add_user("ada", Role.ADMIN, PASSWORD)
        accounts.add_user("vic", Role.VIEWER, PASSWORD)
        token = accounts.issue(ada.id, "api", timedelta(days=1)).token
        bearer = {"Authorization": f"Bearer {token}"}
        cmu = next(p for p in default_model_paths() if p.stem == "cmu")
        ModelCatalog.of_data_folder(settings.data_dir).register(cmu, "walks")
        shoot = httpx.post(f"{url}/api/v1/shoots", json={"name": "Day 2"}, headers=bearer).json()
        imported = httpx.post(
            f"{url}/api/v1/shoots/{shoot['id']}/takes",
            files=[("files", (cmu_walk.name, cmu_walk.read_bytes()))],
            headers=bearer,
            timeout=120,
        ).json()
        assert len(imported["created"]) == 1, imported
        yield {"url": url, "shoot": shoot, "take": imported["created"][0], "bearer": bearer}


def _poll(url: str, run_id: str, bearer: dict[str, str]) -> dict[str, Any]:
    deadline = time.monotonic() + RUN_BOUND_S
    while time.monotonic() < deadline:
        run: dict[str, Any] = httpx.get(f"{url}/api/v1/runs/{run_id}", headers=bearer).json()
        if run["status"] in ("done", "failed"):
            return run
        time.sleep(0.2)
    raise TimeoutError(f"run {run_id} did not finish in {RUN_BOUND_S} s")


def test_admin_picks_the_model_a_shoot_uses(studio: dict[str, Any], chromium: Any) -> None:
    url, shoot_id, bearer = studio["url"], studio["shoot"]["id"], studio["bearer"]
    ARTIFACTS.mkdir(exist_ok=True)
    context = chromium.new_context(viewport={"width": 1300, "height": 900})
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))

    # A viewer sees which model the shoot uses, and no picker.
    sign_in(page, url, "vic")
    open_shoot(page, url, shoot_id)
    assert page.inner_text("#limits-model-name") == "default"
    assert page.locator("#limits-model").count() == 0
    page.click("#sign-out")
    page.wait_for_selector("#signin-form", timeout=60_000)

    # The admin picks the registered model; the choice is saved.
    sign_in(page, url, "ada")
    open_shoot(page, url, shoot_id)
    offered = page.eval_on_selector_all("#limits-model option", "o => o.map(e => e.value)")
    assert offered[0] == "default"
    assert {"canonical", "bandai", "character_creator", "cmu", "walks"} <= set(offered)
    assert page.input_value("#limits-model") == "default"
    # From the keyboard: each arrow key moves the choice, the list keeps the focus, and only
    # the choice it settles on is saved (no save of the models passed over).
    page.focus("#limits-model")
    page.keyboard.press("ArrowDown")
    page.keyboard.press("ArrowDown")
    assert page.evaluate("() => document.activeElement.id") == "limits-model"
    settled = page.input_value("#limits-model")
    assert settled == offered[2]
    page.wait_for_selector("#limits-model-message:has-text('saved')", timeout=30_000)
    assert page.evaluate("() => document.activeElement.id") == "limits-model"
    assert settled in page.inner_text("#limits-model-message")
    assert offered[1] not in page.inner_text("#limits-model-message")
    page.select_option("#limits-model", "walks")
    page.wait_for_selector(
        "#limits-model-message:has-text('saved: runs started from now on use walks')",
        timeout=30_000,
    )
    assert "walks" in page.inner_text("#limits-model-message")
    page.screenshot(path=str(ARTIFACTS / "shoot-limits-model.png"))
    shoot = httpx.get(f"{url}/api/v1/shoots/{shoot_id}", headers=bearer).json()
    assert shoot["limits_model"] == "walks"

    # The take's latest run used the old model: the panel says so, and the admin runs it
    # again from there; the new run uses the shoot's model, the first keeps the one it ran with.
    assert page.inner_text("#limits-model-stale") == (
        "1 take's latest run checked joint limits with another model than walks"
    )
    first = _poll(url, studio["take"]["run_id"], bearer)
    assert first["options"]["limits_model"] == "default"
    # The take table is drawn again once the queued run has finished (the page polls again).
    page.evaluate(
        """() => { window.tableDraws = 0; new MutationObserver(() => { window.tableDraws += 1; })
                   .observe(document.getElementById('take-table-box'), { childList: true }); }"""
    )
    page.click("#limits-rerun")
    page.wait_for_selector("#limits-model-message:has-text('queued')", timeout=60_000)
    assert page.inner_text("#limits-model-message") == "1 run queued with walks"
    assert page.inner_text("#limits-model-stale") == ""
    assert page.locator("#limits-rerun").is_hidden()
    take_id = studio["take"]["take_id"]
    runs = httpx.get(f"{url}/api/v1/takes/{take_id}", headers=bearer).json()["runs"]
    (again,) = [r for r in runs if r["id"] != first["id"]]
    second = _poll(url, again["id"], bearer)
    assert second["status"] == "done", second
    assert second["options"]["limits_model"] == "walks"
    page.wait_for_function("() => window.tableDraws > 0", timeout=30_000)
    assert (
        httpx.get(f"{url}/api/v1/shoots/{shoot_id}", headers=bearer).json()["limits_stale_takes"]
        == 0
    )

    # After a reload the picker shows the saved choice.
    open_shoot(page, url, shoot_id)
    assert page.input_value("#limits-model") == "walks"
    context.close()
    assert not errors, errors
