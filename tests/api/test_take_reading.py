"""How a take was read: chosen at upload (form fields), returned with the take, kept for re-runs."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient

Waiter = Callable[[TestClient, str], dict[str, Any]]
OPENPOSE_FRAME = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose/cam01_json/cam01.0000.json"


def post(client: TestClient, path: Path, **form: str) -> dict[str, Any]:
    with path.open("rb") as handle:
        response = client.post("/api/v1/takes", files={"file": (path.name, handle)}, data=form)
    assert response.status_code == 201, response.text
    body: dict[str, Any] = response.json()
    return body


def test_the_root_reading_is_detected_explained_and_overridable(
    client: TestClient, corpus_dir: Path, wait_for_run: Waiter
) -> None:
    take = corpus_dir / "bvh" / "cmu" / "iclone" / "001_14.bvh"
    detected = post(client, take)
    assert detected["reading"]["root_translation"] == "add"
    assert detected["reading"]["root_translation_reason"].startswith("add (detected)")
    assert "Blender" in detected["reading"]["root_translation_reason"]
    assert detected["reading"]["bind_pose_frames"] == 0
    chosen = post(client, take, root_translation="replace")
    detail = client.get(f"/api/v1/takes/{chosen['id']}").json()
    assert detail["reading"]["read_options"]["root_translation"] == "replace"
    assert detail["reading"]["root_translation_reason"].startswith("replace (chosen by the user)")
    wait_for_run(client, chosen["run_id"])
    # A later run reads the take the same way.
    response = client.post(f"/api/v1/takes/{chosen['id']}/runs", json={"checks": ["twist"]})
    run = wait_for_run(client, response.json()["id"])
    assert run["status"] == "done", run["error"]
    result = client.get(f"/api/v1/runs/{run['id']}/result").json()
    assert result["summary"]["root_translation"] == "replace"


def test_a_bind_pose_first_frame_is_reported_with_the_take_and_the_run(
    client: TestClient, corpus_dir: Path, wait_for_run: Waiter
) -> None:
    # 007_12 starts with a T-pose frame ("Imported" status in the corpus README).
    take = post(client, corpus_dir / "bvh" / "cmu" / "iclone" / "007_12.bvh")
    assert take["reading"]["bind_pose_frames"] == 1
    run = wait_for_run(client, take["run_id"])
    assert run["status"] == "done", run["error"]
    result = client.get(f"/api/v1/runs/{run['id']}/result").json()
    assert result["summary"]["bind_pose_frames"] == 1


def test_an_assumed_frame_rate_is_shown_and_can_be_set_at_upload(
    client: TestClient, corpus_dir: Path
) -> None:
    frame = corpus_dir / OPENPOSE_FRAME
    assumed = post(client, frame)["reading"]
    assert assumed["fps"] == 30.0
    assert "fps 30 assumed: OpenPose JSON stores no frame rate" in assumed["assumptions"]
    assert assumed["length_unit"] == "px"
    chosen = post(client, frame, fps="25")
    assert chosen["fps"] == 25.0
    assert not any("fps" in a for a in chosen["reading"]["assumptions"])
    assert chosen["reading"]["read_options"]["fps"] == 25.0


def test_bad_reading_fields_are_refused(client: TestClient, corpus_dir: Path) -> None:
    frame = corpus_dir / OPENPOSE_FRAME
    for form in ({"fps": "0"}, {"length_unit": "furlong"}, {"root_translation": "sideways"}):
        with frame.open("rb") as handle:
            response = client.post("/api/v1/takes", files={"file": (frame.name, handle)}, data=form)
        assert response.status_code == 422, form
    assert client.get("/api/v1/takes").json()["total"] == 0
