"""A shoot's later runs use its reviewers' decisions: recorded, named in the readout, and never
on an approved take."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient
from tests.api.conftest import poll_run

from mocapqa.config import Settings
from mocapqa.jobs.run_folder import RunFolder
from mocapqa.store.files import FileStore
from mocapqa.twist.reviewer_prior import ReviewerPrior

API = "/api/v1"
KNEES = "bvh/cmu/iclone/005_05.bvh"


def _import(client: TestClient, shoot_id: str, name: str, data: bytes) -> dict[str, str]:
    response = client.post(f"{API}/shoots/{shoot_id}/takes", files=[("files", (name, data))])
    assert response.status_code == 201, response.text
    created: dict[str, str] = response.json()["created"][0]
    run = poll_run(client, created["run_id"])
    assert run["status"] == "done", run["error"]
    return created


def _twist(client: TestClient, run_id: str) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    report: dict[str, Any] = client.get(f"{API}/runs/{run_id}/result").json()
    return report, [f for f in report["findings"] if f["kind"] == "twist"]


def _accept(client: TestClient, run_id: str, findings: list[dict[str, Any]]) -> None:
    for finding in findings:
        response = client.post(
            f"{API}/runs/{run_id}/intervals/{finding['id']}/decisions", json={"decision": "accept"}
        )
        assert response.status_code == 201, response.text


def test_a_later_run_of_the_shoot_records_and_names_the_reviewers_prior(
    client: TestClient, corpus_dir: Path, settings: Settings
) -> None:
    data = (corpus_dir / KNEES).read_bytes()
    shoot = client.post(f"{API}/shoots", json={"name": "knees"}).json()["id"]
    first = _import(client, shoot, "first.bvh", data)
    report, findings = _twist(client, first["run_id"])
    assert "reviewer_prior" not in report  # nothing decided yet in the shoot
    left = [f for f in findings if not f["applied"] and "calibrated probability" in f["readout"]]
    assert left, [f["readout"] for f in findings]
    joint = left[0]["joint"]
    on_joint = [f for f in findings if f["joint"] == joint]
    # Three takes of the shoot reviewed: every interval on that joint accepted.
    second = _import(client, shoot, "second.bvh", data)
    _accept(client, first["run_id"], on_joint)
    _accept(client, second["run_id"], on_joint)
    fourth = _import(client, shoot, "fourth.bvh", data)
    _accept(client, fourth["run_id"], on_joint)

    third = _import(client, shoot, "third.bvh", data)
    report, later = _twist(client, third["run_id"])
    summary = report["reviewer_prior"]
    assert (summary["accepted"], summary["rejected"]) == (3 * len(on_joint), 0)
    assert (summary["joints"], summary["runs"]) == (1, 3)
    folder = RunFolder.of(FileStore(settings.data_dir), third["run_id"])
    recorded = ReviewerPrior.from_json(json.loads(folder.prior.read_text(encoding="utf-8")))
    assert recorded.content_hash == summary["hash"]  # the run can be made again from it
    assert sorted(recorded.runs) == sorted(r["run_id"] for r in (first, second, fourth))
    assert not RunFolder.of(FileStore(settings.data_dir), first["run_id"]).prior.exists()
    by_id = {f["id"]: f for f in later}
    moved = by_id[left[0]["id"]]
    rig = recorded.labels[0].rig
    _, weighing, _ = recorded.shift(rig, joint, left[0]["confidence"])
    assert weighing >= 3  # the interval itself, decided on three takes, and any scored alike
    phrase = f"by {weighing} accepted intervals on this joint in this shoot"
    assert phrase in moved["readout"], moved["readout"]
    assert "which changed the default" in moved["readout"]
    assert moved["applied"]
    assert not left[0]["applied"]
    assert moved["confidence"] == left[0]["confidence"]  # the calibrated probability is kept
    assert all(by_id[f["id"]] == f for f in findings if f["joint"] != joint)
    # The decided takes' own runs are unchanged: a prior shapes later runs only.
    assert _twist(client, first["run_id"])[1] == findings

    # A take's own decisions are not in its prior (its decided download applies them).
    again = client.post(f"{API}/takes/{first['take_id']}/runs", json={})
    assert again.status_code == 201, again.text
    run = poll_run(client, again.json()["id"])
    assert run["status"] == "done", run["error"]
    assert _twist(client, run["id"])[0]["reviewer_prior"]["accepted"] == 2 * len(on_joint)

    # An approved take is never changed by a decision: its next run has no prior.
    review = client.post(f"{API}/takes/{third['take_id']}/reviews", json={"status": "approved"})
    assert review.status_code == 201, review.text
    rerun = client.post(f"{API}/takes/{third['take_id']}/runs", json={})
    assert rerun.status_code == 201, rerun.text
    run = poll_run(client, rerun.json()["id"])
    assert run["status"] == "done", run["error"]
    report, approved = _twist(client, run["id"])
    assert "reviewer_prior" not in report
    assert approved == findings
