"""A shoot's joint-limits model through the API (SQLite and PostgreSQL): who may choose it,
unknown names refused, and the runs of the shoot's takes recording and using it."""

from __future__ import annotations

import time
from collections.abc import Iterator
from datetime import timedelta
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import RUN_BOUND_S

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.limits.catalog import MODELS_FOLDER, ModelCatalog
from mocapqa.limits.storage import default_model_paths
from mocapqa.render.service import RenderService
from mocapqa.store.accounts import Accounts
from mocapqa.store.roles import Role

API = "/api/v1"
ROLES = {"admin": Role.ADMIN, "viewer": Role.VIEWER, "rev": Role.REVIEWER}
Team = tuple[TestClient, dict[str, dict[str, str]], Settings]


@pytest.fixture
def team(settings: Settings, renderer: RenderService) -> Iterator[Team]:
    """An app with an admin, a viewer and a reviewer, and each one's Bearer header."""
    settings = settings.model_copy(update={"job_workers": 1})
    with TestClient(create_app(settings, renderer=renderer)) as client:
        accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
        headers: dict[str, dict[str, str]] = {"anonymous": {}}
        for name, role in ROLES.items():
            user = accounts.add_user(name, role, "correct horse battery")
            token = accounts.issue(user.id, "api", timedelta(days=1))
            headers[name] = {"Authorization": f"Bearer {token.token}"}
        yield client, headers, settings


def _shipped(stem: str) -> Path:
    return next(p for p in default_model_paths() if p.stem == stem)


def _import(client: TestClient, shoot: str, path: Path, headers: dict[str, str]) -> list[str]:
    part = [("files", (path.name, path.read_bytes()))]
    made = client.post(f"{API}/shoots/{shoot}/takes", files=part, headers=headers)
    assert made.status_code == 201, made.text
    created = made.json()["created"][0]
    return [str(created["take_id"]), str(created["run_id"])]


def _poll(client: TestClient, run_id: str, headers: dict[str, str]) -> dict[str, Any]:
    """The run once done or failed (a generous bound: a hang, not a slow machine, fails)."""
    deadline = time.monotonic() + RUN_BOUND_S
    while time.monotonic() < deadline:
        run: dict[str, Any] = client.get(f"{API}/runs/{run_id}", headers=headers).json()
        if run["status"] in ("done", "failed"):
            return run
        time.sleep(0.05)
    raise TimeoutError(f"run {run_id} did not finish in {RUN_BOUND_S} s")


def test_only_admins_choose_and_unknown_models_are_refused(team: Team) -> None:
    client, headers, settings = team
    made = client.post(f"{API}/shoots", json={"name": "day1"}, headers=headers["rev"])
    shoot = made.json()["id"]
    assert made.json()["limits_model"] == "default"
    listed = client.get(f"{API}/limits-models", headers=headers["viewer"])
    assert listed.status_code == 200
    names = [m["name"] for m in listed.json()]
    assert names[0] == "default"
    assert {"canonical", "bandai", "cmu"} <= set(names)
    assert client.get(f"{API}/limits-models").status_code == 401
    path = f"{API}/shoots/{shoot}/limits-model"
    for who, status in (("anonymous", 401), ("viewer", 403), ("rev", 403), ("admin", 200)):
        answer = client.put(path, json={"name": "canonical"}, headers=headers[who])
        assert answer.status_code == status, (who, answer.text)
    # viewers see the choice
    seen = client.get(f"{API}/shoots/{shoot}", headers=headers["viewer"]).json()
    assert seen["limits_model"] == "canonical"
    # an unknown name: 422 naming the field, nothing changed; an unknown shoot: 404
    unknown = client.put(path, json={"name": "nope"}, headers=headers["admin"])
    assert unknown.status_code == 422
    assert unknown.json()["detail"].startswith("limits_model: Expected one of the limits models")
    bad = client.put(path, json={"name": "../cmu"}, headers=headers["admin"])
    assert bad.status_code == 422
    missing = client.put(f"{API}/shoots/0000/limits-model", json={"name": "cmu"},
                         headers=headers["admin"])  # fmt: skip
    assert missing.status_code == 404
    assert client.get(f"{API}/shoots/{shoot}").status_code == 401
    assert (
        client.get(f"{API}/shoots/{shoot}", headers=headers["admin"]).json()["limits_model"]
        == "canonical"
    )
    # a registered model appears once its file is in the data folder
    ModelCatalog(settings.data_dir / MODELS_FOLDER).register(_shipped("cmu"), "walks")
    names = [m["name"] for m in client.get(f"{API}/limits-models", headers=headers["rev"]).json()]
    assert names[-1] == "walks"
    assert client.put(path, json={"name": "walks"}, headers=headers["admin"]).status_code == 200
    log = client.get(f"{API}/audit?limit=50", headers=headers["admin"]).json()["items"]
    details = [e["detail"] for e in log if e["action"] == "shoot_limits_model"]
    assert sorted(details) == ["canonical → walks", "default → canonical"]
    paths = client.get("/openapi.json").json()["paths"]
    assert {"200", "401", "403", "404", "422"} <= set(
        paths[f"{API}/shoots/{{shoot_id}}/limits-model"]["put"]["responses"]
    )


def test_runs_of_a_shoot_use_its_model(team: Team, cmu_walk: Path) -> None:
    client, headers, settings = team
    admin = headers["admin"]
    shoot = client.post(f"{API}/shoots", json={"name": "walks"}, headers=admin).json()["id"]
    path = f"{API}/shoots/{shoot}/limits-model"
    # Bandai's own model covers only Bandai skeletons: the CMU walk's check reports no model.
    assert client.put(path, json={"name": "bandai"}, headers=admin).status_code == 200
    take, first = _import(client, shoot, cmu_walk, admin)
    run = _poll(client, first, admin)
    assert run["status"] == "done", run
    assert run["options"]["limits_model"] == "bandai"
    assert run["summary"]["steps"]["limits"] == "no_model"
    # A model registered in the data folder (here a copy of the shipped CMU model), chosen
    # for the shoot, is used by the take's next run; the first run keeps its model.
    ModelCatalog(settings.data_dir / MODELS_FOLDER).register(_shipped("cmu"), "walks")
    assert client.put(path, json={"name": "walks"}, headers=admin).status_code == 200
    again = client.post(f"{API}/takes/{take}/runs", headers=admin)
    assert again.status_code == 201, again.text
    second = _poll(client, again.json()["id"], admin)
    assert second["status"] == "done", second
    assert second["options"]["limits_model"] == "walks"
    assert second["summary"]["steps"]["limits"] == "done"
    report = client.get(f"{API}/runs/{second['id']}/result", headers=admin).json()
    assert "model walks (cmu, the rig's own model)" in report["steps"]["limits"]["message"]
    assert (
        client.get(f"{API}/runs/{run['id']}", headers=admin).json()["options"]["limits_model"]
        == "bandai"
    )
    # a run may not pick its own model: the shoot decides
    refused = client.post(f"{API}/takes/{take}/runs", json={"limits_model": "cmu"}, headers=admin)
    assert refused.status_code == 422
    # a take outside any shoot uses the default choice
    with cmu_walk.open("rb") as handle:
        single = client.post(f"{API}/takes", files={"file": (cmu_walk.name, handle)}, headers=admin)
    assert single.status_code == 201, single.text
    alone = _poll(client, single.json()["run_id"], admin)
    assert alone["options"]["limits_model"] == "default"
    assert alone["summary"]["steps"]["limits"] == "done"


def test_takes_run_with_an_older_model_are_counted_and_run_again(
    settings: Settings, renderer: RenderService, corpus_dir: Path
) -> None:
    # One queued run per user at a time, so the re-runs come in two requests.
    settings = settings.model_copy(update={"job_workers": 1, "max_queued_runs_per_user": 1})
    with TestClient(create_app(settings, renderer=renderer)) as client:
        accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
        headers: dict[str, dict[str, str]] = {"anonymous": {}}
        for name, role in ROLES.items():
            user = accounts.add_user(name, role, "correct horse battery")
            token = accounts.issue(user.id, "api", timedelta(days=1))
            headers[name] = {"Authorization": f"Bearer {token.token}"}
        admin = headers["admin"]
        shoot = client.post(f"{API}/shoots", json={"name": "day2"}, headers=admin).json()["id"]
        bandai = corpus_dir / "bvh" / "bandai"
        takes = {}
        for name in ("dataset-1_dash_normal_001.bvh", "dataset-2_wave-left-hand_active_011.bvh"):
            take, run = _import(client, shoot, bandai / name, admin)
            assert _poll(client, run, admin)["options"]["limits_model"] == "default"
            takes[take] = run
        assert client.get(f"{API}/shoots/{shoot}", headers=admin).json()["limits_stale_takes"] == 0
        reruns = f"{API}/shoots/{shoot}/limits-reruns"
        nothing = client.post(reruns, headers=admin)
        assert nothing.status_code == 200
        assert nothing.json() == {"limits_model": "default", "queued": [], "remaining": 0}

        chosen = client.put(
            f"{API}/shoots/{shoot}/limits-model", json={"name": "bandai"}, headers=admin
        )
        assert chosen.json()["limits_stale_takes"] == 2
        listed = client.get(f"{API}/shoots", headers=headers["viewer"]).json()
        assert [s["limits_stale_takes"] for s in listed if s["id"] == shoot] == [2]
        for who, status in (("anonymous", 401), ("viewer", 403), ("rev", 403)):
            assert client.post(reruns, headers=headers[who]).status_code == status, who
        assert client.post(f"{API}/shoots/0000/limits-reruns", headers=admin).status_code == 404
        runner = client.app.state.services.runner  # type: ignore[attr-defined]
        key = f"user:{accounts.get_user('admin').id}"
        with runner.places(key, 1, 1):  # the caller's line is full: nothing is queued
            full = client.post(reruns, headers=admin)
            assert full.status_code == 429, full.text
        assert client.get(f"{API}/shoots/{shoot}", headers=admin).json()["limits_stale_takes"] == 2

        new_runs = []
        for remaining in (1, 0):  # one free place per request
            answer = client.post(reruns, headers=admin)
            assert answer.status_code == 200, answer.text
            body = answer.json()
            assert body["limits_model"] == "bandai"
            assert body["remaining"] == remaining
            (entry,) = body["queued"]
            assert entry["take_id"] in takes
            done = _poll(client, entry["run_id"], admin)
            assert done["status"] == "done", done
            assert done["options"]["limits_model"] == "bandai"
            assert done["summary"]["steps"]["limits"] == "done"
            old = client.get(f"{API}/runs/{takes[entry['take_id']]}", headers=admin).json()
            assert {**old["options"], "limits_model": "bandai"} == done["options"]
            new_runs.append(entry["take_id"])
        assert sorted(new_runs) == sorted(takes)
        seen = client.get(f"{API}/shoots/{shoot}", headers=headers["viewer"]).json()
        assert seen["limits_stale_takes"] == 0
        log = client.get(f"{API}/audit?limit=50", headers=admin).json()["items"]
        details = sorted(e["detail"] for e in log if e["action"] == "shoot_limits_reruns")
        assert details == [
            "0 run(s) with default, 0 left",
            "1 run(s) with bandai, 0 left",
            "1 run(s) with bandai, 1 left",
        ]
