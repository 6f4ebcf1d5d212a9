"""Run options checked at the request, the OpenAPI telling the truth, and crash hygiene."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path
from typing import Any

import pytest
from fastapi.routing import APIRoute
from fastapi.testclient import TestClient
from tests.api.conftest import Uploader, Waiter, make_settings
from tests.api.test_rendered import TRC

from mocapqa.api.app import API_PREFIX, ROUTERS, create_app
from mocapqa.api.errors import STATUS_MEANING
from mocapqa.config import Settings
from mocapqa.render.service import RenderService
from mocapqa.store.repository import Repository


@pytest.mark.parametrize(
    ("options", "field"),
    [
        ({"filter_method": "adaptive"}, "filter_method"),
        ({"filter_method": "quat-pd", "filter_params": {"no_such": 1}}, "filter_params.no_such"),
        ({"filter_method": "quat-pd", "filter_preset": "no-such"}, "filter_preset"),
        ({"filter_preset": "default"}, "filter_preset"),
        ({"twist_method": "magic"}, "body.twist_method"),
        # Durations and frequencies out of any filter's range, and ids that int() alone
        # would read (10 from "1_0", other scripts' digits).
        (
            {"filter_method": "quat-pd", "filter_params": {"natural_frequency_hz": 1e12}},
            "filter_params.natural_frequency_hz",
        ),
        (
            {"filter_method": "butterworth", "filter_params": {"cutoff_hz": 1e-300}},
            "filter_params.cutoff_hz",
        ),
        # The walk runs at 120 fps: a cut-off of 61 Hz is past its Nyquist frequency.
        (
            {"filter_method": "butterworth", "filter_params": {"cutoff_hz": 61.0}},
            "filter_params.cutoff_hz",
        ),
        ({"twist_apply": "1_0"}, "twist_apply"),
        ({"twist_apply": "١,٢"}, "twist_apply"),
    ],
)
def test_bvh_run_options_are_checked_at_the_request(
    client: TestClient, cmu_walk: Path, upload: Uploader, options: dict[str, Any], field: str
) -> None:
    take = upload(client, cmu_walk)
    response = client.post(f"/api/v1/takes/{take['id']}/runs", json=options)
    assert response.status_code == 422, response.text
    body = response.json()
    assert field in (body.get("field") or body["detail"])
    assert len(client.get(f"/api/v1/takes/{take['id']}").json()["runs"]) == 1


def test_keypoint_run_options_are_checked_at_the_request(
    client: TestClient, corpus_dir: Path, upload: Uploader
) -> None:
    take = upload(client, corpus_dir / TRC)
    bad = client.post(f"/api/v1/takes/{take['id']}/runs", json={"filter_method": "quat-pd"})
    assert bad.status_code == 422
    assert bad.json()["field"] == "filter_method"
    window = {"filter_method": "adaptive", "filter_params": {"window_s": 1e9}}
    bad = client.post(f"/api/v1/takes/{take['id']}/runs", json=window)
    assert bad.status_code == 422
    assert bad.json()["field"] == "filter_params.window_s"
    assert "0.0001 to 60 s" in bad.json()["detail"]
    params = {"filter_method": "kalman", "filter_params": {"process_noise": "loud"}}
    bad = client.post(f"/api/v1/takes/{take['id']}/runs", json=params)
    assert bad.status_code == 422
    assert bad.json()["field"] == "filter_params.process_noise"
    mapped = {"mapping": {"left_upper_arm": "LeftArm"}}
    bad = client.post(f"/api/v1/takes/{take['id']}/runs", json=mapped)
    assert bad.status_code == 422
    assert bad.json()["field"] == "mapping"
    good = client.post(f"/api/v1/takes/{take['id']}/runs", json={"filter_preset": "note"})
    assert good.status_code == 201


def test_openapi_documents_every_status_each_route_answers(client: TestClient) -> None:
    spec = client.get("/openapi.json").json()
    error_ref = "#/components/schemas/ErrorOut"
    routes = [
        (API_PREFIX + r.path, r)
        for router, _ in ROUTERS
        for r in router.routes
        if isinstance(r, APIRoute) and r.include_in_schema
    ]
    assert len(routes) >= 12
    for path, route in routes:
        for method in route.methods:
            operation = spec["paths"][path][method.lower()]
            documented = {int(s) for s in operation["responses"]}
            assert {400, 422} <= documented, path
            for status in documented - {200, 201, 204}:
                assert status in STATUS_MEANING
                schema = operation["responses"][str(status)]["content"]["application/json"]
                assert schema["schema"]["$ref"] == error_ref, (path, status)
            if "{take_id}" in path or "{run_id}" in path:
                assert 404 in documented, path
            if method in ("POST", "DELETE"):
                assert 403 in documented, path
            if method in ("POST", "PUT", "PATCH", "DELETE"):
                # Every request body is bounded (max_request_kb, max_upload_mb): 413 over it.
                assert 413 in documented, (method, path)
    upload = spec["paths"]["/api/v1/takes"]["post"]["responses"]
    assert {"413", "415", "429"} <= set(upload)
    run_status = spec["components"]["schemas"]["RunOut"]["properties"]["status"]
    assert run_status["enum"] == ["queued", "running", "done", "failed"]
    status_query = next(
        p for p in spec["paths"]["/api/v1/takes"]["get"]["parameters"] if p["name"] == "status"
    )
    assert "enum" in str(status_query["schema"])


def test_names_are_echoed_without_controls(client: TestClient, cmu_walk: Path) -> None:
    with cmu_walk.open("rb") as handle:
        name = "walk\u202egnp.bvh"
        response = client.post("/api/v1/takes", files={"file": (name, handle)})
    assert response.status_code == 201
    assert response.json()["name"] == "walkgnp.bvh"
    take_id = response.json()["id"]
    # A review stored before accounts keeps its free-text reviewer, shown cleaned; the body's
    # reviewer field is ignored now (the reviewer is who is signed in).
    services = client.app.state.services  # type: ignore[attr-defined]
    services.repository.add_review(take_id, "approved", "", "ann\u2066e\u0000")
    reviews = client.get(f"/api/v1/takes/{take_id}/reviews").json()
    assert reviews[0]["reviewer"] == "anne"
    review = {"status": "approved", "reviewer": "mallory"}
    answer = client.post(f"/api/v1/takes/{take_id}/reviews", json=review)
    assert answer.json()["reviewer"] == "anonymous"  # a server without users


def test_deleting_a_take_cancels_its_queued_run_and_removes_its_files(
    tmp_path: Path, cmu_walk: Path, renderer: RenderService, upload: Uploader, wait_for_run: Waiter
) -> None:
    settings = make_settings("sqlite", tmp_path, job_workers=1)
    with TestClient(create_app(settings, renderer=renderer)) as client:
        first = upload(client, cmu_walk)
        second = upload(client, cmu_walk)  # waits behind the first (one worker)
        assert client.delete(f"/api/v1/takes/{second['id']}").status_code == 204
        assert client.delete(f"/api/v1/takes/{first['id']}").status_code == 204
        runner = client.app.state.services.runner  # type: ignore[attr-defined]
        runner.wait(first["run_id"], timeout_s=900)
        runner.wait(second["run_id"], timeout_s=900)
        for sub in ("takes", "runs", "incoming"):
            assert list((settings.data_dir / sub).iterdir()) == [], sub


def test_start_sweeps_incoming_and_fails_a_run_interrupted_twice(
    tmp_path: Path, cmu_walk: Path, renderer: RenderService, upload: Uploader, wait_for_run: Waiter
) -> None:
    settings = make_settings("sqlite", tmp_path)
    with TestClient(create_app(settings, renderer=renderer)) as client:
        take = upload(client, cmu_walk)
        wait_for_run(client, take["run_id"])
    repository = Repository(settings.resolved_database_url)
    again = repository.add_run(take["id"], {})
    repository.mark_running(again)
    repository.mark_running(again)  # started twice, interrupted twice
    repository.close()
    (settings.data_dir / "incoming" / "upload-partial.bvh").write_bytes(b"HIERARCHY")
    with TestClient(create_app(settings, renderer=renderer)) as client:
        run = client.get(f"/api/v1/runs/{again}").json()
        assert run["status"] == "failed"
        assert run["attempts"] == 2
        assert "stopped during it 2 times" in run["error"]
    assert list((settings.data_dir / "incoming").iterdir()) == []


def test_a_database_without_the_attempts_column_still_opens(tmp_path: Path) -> None:
    """A database made before ``runs.attempts`` existed (the first release's, in
    tests/data/legacy) gets the column when opened."""
    path = tmp_path / "old.sqlite3"
    legacy = Path(__file__).resolve().parents[1] / "data" / "legacy"
    shutil.copyfile(legacy / "228f57d.sqlite3", path)
    with sqlite3.connect(path) as conn:
        columns = [row[1] for row in conn.execute("PRAGMA table_info(runs)")]
        (run_id,) = conn.execute("SELECT id FROM runs WHERE status = 'done' LIMIT 1").fetchone()
    assert "attempts" not in columns
    repository = Repository(f"sqlite:///{path}")
    run = repository.get_run(run_id)
    repository.close()
    assert run["attempts"] == 0
    assert run["status"] == "done"


def test_settings_document_every_limit() -> None:
    docs = (Path(__file__).resolve().parents[2] / "docs" / "api.md").read_text()
    limits = [name for name in Settings.model_fields if name.startswith(("max_", "stream_"))]
    limits += ["uploads_per_minute_per_user", "allowed_hosts", "cors_origins"]
    missing = [name for name in limits if name not in docs]
    assert missing == []


def test_queued_runs_per_user_are_limited(
    tmp_path: Path, cmu_walk: Path, renderer: RenderService, upload: Uploader
) -> None:
    settings = make_settings("sqlite", tmp_path, max_queued_runs_per_user=2, job_workers=1)
    with TestClient(create_app(settings, renderer=renderer)) as client:
        runner = client.app.state.services.runner  # type: ignore[attr-defined]
        take = upload(client, cmu_walk)
        answers = [client.post(f"/api/v1/takes/{take['id']}/runs", json={}) for _ in range(4)]
        statuses = [a.status_code for a in answers]
        # the upload's run and the first extra one fill the quota while the worker is busy
        assert 429 in statuses
        refused = answers[statuses.index(429)]
        assert refused.json()["error"] == "RateLimitError"
        assert "max_queued_runs_per_user" in refused.json()["detail"]
        assert int(refused.headers["retry-after"]) >= 1
        for answer in answers:
            if answer.status_code == 201:
                runner.wait(answer.json()["id"], timeout_s=900)
        runner.wait(take["run_id"], timeout_s=900)
        assert client.post(f"/api/v1/takes/{take['id']}/runs", json={}).status_code == 201
