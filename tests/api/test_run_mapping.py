"""The rig mapping as a run option: used by the run, reported, refused when it names no role."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]


def test_a_run_uses_the_mapping_option(
    client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(client, cmu_walk)
    assert wait_for_run(client, created["run_id"])["status"] == "done"
    first = client.get(f"/api/v1/runs/{created['run_id']}/result").json()
    assert first["summary"]["roles"]["left_hand"] == "LeftHand"
    assert first["summary"]["missing_roles"] == []
    assert first["summary"]["root_translation"] == "replace"
    options = {"checks": ["twist"], "max_points": 50, "mapping": {"left_hand": "LeftFingerBase"}}
    response = client.post(f"/api/v1/takes/{created['id']}/runs", json=options)
    assert response.status_code == 201, response.text
    run = wait_for_run(client, response.json()["id"])
    assert run["status"] == "done", run["error"]
    assert run["options"]["mapping"] == {"left_hand": "LeftFingerBase"}
    result = client.get(f"/api/v1/runs/{run['id']}/result").json()
    assert result["summary"]["roles"]["left_hand"] == "LeftFingerBase"


def test_a_mapping_without_role_keys_is_refused(
    client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(client, cmu_walk)
    wait_for_run(client, created["run_id"])
    for mapping in ({"left_wrist": "LeftHand"}, {"left_hand": ""}, {"left_hand": 3}):
        response = client.post(f"/api/v1/takes/{created['id']}/runs", json={"mapping": mapping})
        assert response.status_code == 422, mapping
        assert "mapping" in response.text
    # A joint the take does not have is refused when the run is asked for, naming the role.
    response = client.post(
        f"/api/v1/takes/{created['id']}/runs", json={"mapping": {"left_hand": "NoSuchJoint"}}
    )
    assert response.status_code == 422, response.text
    assert response.json()["field"] == "mapping.left_hand"
    assert "NoSuchJoint" in response.json()["detail"]
    assert len(client.get(f"/api/v1/takes/{created['id']}").json()["runs"]) == 1
