"""Upload → run → download → re-read, and every bad input answered with its 4xx, storing nothing."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import make_settings

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.io.bvh import parse_bvh, read_bvh
from mocapqa.io.formats import read_take
from mocapqa.jobs.demo import demo_paths
from mocapqa.render.service import RenderService

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]


def stored_nothing(client: TestClient, settings: Settings) -> None:
    assert client.get("/api/v1/takes").json()["total"] == 0
    for sub in ("takes", "runs", "incoming"):
        assert list((settings.data_dir / sub).iterdir()) == []


def test_health_answers_ok(client: TestClient) -> None:
    response = client.get("/api/v1/health")
    assert response.status_code == 200
    assert response.json()["status"] == "ok"


def test_upload_runs_and_the_corrected_bvh_reads_back(
    client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(client, cmu_walk)
    assert created["n_frames"] == 524
    assert created["n_joints"] == 31
    run = wait_for_run(client, created["run_id"])
    assert run["status"] == "done", run["error"]
    assert run["progress"] == 100
    assert run["options"]["checks"] == ["twist", "limits", "filter", "markers", "feet"]
    download = client.get(f"/api/v1/runs/{created['run_id']}/download/bvh")
    assert download.status_code == 200
    corrected = parse_bvh(download.content, "corrected.bvh")
    original = read_bvh(cmu_walk)
    assert corrected.skeleton.names == original.skeleton.names
    assert corrected.n_frames == original.n_frames
    listed = client.get("/api/v1/takes").json()
    assert [t["id"] for t in listed["items"]] == [created["id"]]
    assert listed["items"][0]["status"] == "done"


def test_injected_twist_errors_are_found_and_removed(
    client: TestClient, upload: Uploader, wait_for_run: Waiter
) -> None:
    # Injected intervals of the demo take, from its README (the injection protocol's truth).
    injected = {("LeftArm", 243, 260), ("LeftArm", 387, 399), ("LeftLeg", 134, 144)}
    demo_bvh = demo_paths()[0]
    created = upload(client, demo_bvh)
    assert wait_for_run(client, created["run_id"])["status"] == "done"
    result = client.get(f"/api/v1/runs/{created['run_id']}/result").json()
    found = [(f["joint"], f["start_frame"], f["end_frame"]) for f in result["findings"]]
    for joint, start, end in injected:
        assert any(j == joint and s <= end and start <= e for j, s, e in found), (joint, found)
    assert result["steps"]["twist"]["state"] == "done"
    chains = {c["joint"]: c for c in result["series"]["twist"]["chains"]}
    assert max(abs(v) for v in chains["LeftArm"]["offset_deg"]) > 45.0
    corrected = parse_bvh(
        client.get(f"/api/v1/runs/{created['run_id']}/download/bvh").content, "c.bvh"
    )
    raw = read_bvh(demo_bvh)
    arm = raw.skeleton.index("LeftArm")
    dots = np.abs(np.sum(corrected.quats[250, arm] * raw.quats[250, arm]))
    assert dots < np.cos(np.radians(20.0))  # the 94.5° shift at frames 243–260 was undone


def test_keypoint_take_is_filtered_and_downloads_read_back(
    client: TestClient, corpus_dir: Path, upload: Uploader, wait_for_run: Waiter, tmp_path: Path
) -> None:
    trc = corpus_dir / "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d"
    created = upload(client, trc / "S00_P00_T01_BalancingTrial_0-100.trc")
    assert created["kind"] == "keypoints"
    run = wait_for_run(client, created["run_id"])
    assert run["status"] == "done", run["error"]
    result = client.get(f"/api/v1/runs/{created['run_id']}/result").json()
    weights = result["series"]["filter"]["weights"]
    total = np.sum([weights[name]["mean"] for name in ("kalman", "one_euro", "ema")], axis=0)
    np.testing.assert_allclose(total, 1.0, atol=1e-3)
    for kind in ("csv", "trc"):
        response = client.get(f"/api/v1/runs/{created['run_id']}/download/{kind}")
        assert response.status_code == 200
        path = tmp_path / f"filtered.{kind}"
        path.write_bytes(response.content)
        sequence = read_take(path)
        assert sequence.n_frames == created["n_frames"]
    missing = client.get(f"/api/v1/runs/{created['run_id']}/download/bvh")
    assert missing.status_code == 404


@pytest.mark.parametrize(
    ("name", "content", "status", "error", "pattern"),
    [
        # Each message names the file as the user sent it, not the server's temporary copy,
        # then the line when there is one, then what was expected and what came.
        (
            "broken.bvh",
            b"HIERARCHY\nROOT Hips\n{\n",
            422,
            "ParseError",
            "broken.bvh, line 3: Expected 'OFFSET', 'CHANNELS', 'JOINT', 'End' or '}', got end",
        ),
        (
            "empty.bvh",
            b"",
            422,
            "ParseError",
            "empty.bvh: Expected a non-empty file, got 0 bytes",
        ),
        (
            "picture.png",
            b"\x89PNG\r\n\x1a\n0000",
            415,
            "UnsupportedFormatError",
            "got an unrecognised file 'picture.png'",
        ),
        ("notes.txt", b"hello", 415, "UnsupportedFormatError", "unrecognised file 'notes.txt'"),
        # A TRC cut short after its header keys: the file and line, and what a TRC needs.
        (
            "numbers.trc",
            b"PathFileType\t4\t(X/Y/Z)\tx.trc\nnonsense\n",
            422,
            "ParseError",
            "numbers.trc, line 2: Expected a TRC header of 3 lines and a marker row",
        ),
    ],
)
def test_bad_uploads_are_refused_and_store_nothing(
    client: TestClient,
    settings: Settings,
    name: str,
    content: bytes,
    status: int,
    error: str,
    pattern: str,
) -> None:
    response = client.post("/api/v1/takes", files={"file": (name, content)})
    assert response.status_code == status, response.text
    body = response.json()
    assert body["error"] == error, body
    assert pattern in body["detail"], body
    if status == 415:  # the formats a take may be in, named
        assert body["detail"].startswith("Expected one of bvh, trc, "), body
    stored_nothing(client, settings)


def test_parse_errors_name_the_file_and_line(client: TestClient, settings: Settings) -> None:
    bvh = (
        b"HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 zero\n"
        b" CHANNELS 3 Xrotation Yrotation Zrotation\n}\nMOTION\n"
    )
    response = client.post("/api/v1/takes", files={"file": ("bad.bvh", bvh)})
    assert response.status_code == 422
    body = response.json()
    assert body["line"] == 4
    assert body["detail"].startswith("bad.bvh, line 4")
    assert "OFFSET" in body["message"]
    stored_nothing(client, settings)


def test_missing_file_field_is_422(client: TestClient) -> None:
    response = client.post("/api/v1/takes", data={"other": "x"})
    assert response.status_code == 422


def test_too_large_upload_is_413_and_stores_nothing(
    tmp_path: Path, cmu_walk: Path, renderer: RenderService
) -> None:
    settings = make_settings("sqlite", tmp_path, max_upload_mb=0.1)
    with TestClient(create_app(settings, renderer=renderer)) as client:
        with cmu_walk.open("rb") as handle:
            response = client.post("/api/v1/takes", files={"file": ("walk.bvh", handle)})
        assert response.status_code == 413
        assert "at most 100000 bytes" in response.json()["detail"]
        stored_nothing(client, settings)


def test_take_detail_delete_and_unknown_ids(
    client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter, settings: Settings
) -> None:
    created = upload(client, cmu_walk)
    wait_for_run(client, created["run_id"])
    detail = client.get(f"/api/v1/takes/{created['id']}").json()
    assert [r["id"] for r in detail["runs"]] == [created["run_id"]]
    thumbnail = client.get(f"/api/v1/takes/{created['id']}/thumbnail")
    assert thumbnail.status_code == 200
    assert thumbnail.headers["content-type"] == "image/png"
    assert thumbnail.content.startswith(b"\x89PNG\r\n\x1a\n")
    assert client.delete(f"/api/v1/takes/{created['id']}").status_code == 204
    assert client.get(f"/api/v1/takes/{created['id']}").status_code == 404
    assert client.get(f"/api/v1/runs/{created['run_id']}").status_code == 404
    assert client.get("/api/v1/takes/nonexistent").status_code == 404
    assert client.get("/api/v1/runs/0123/download/bvh").status_code == 404
    stored_nothing(client, settings)


@pytest.mark.parametrize("suffix", [".bvh", ".trc", ".csv", ".json", ".npy", ".npz", ".pbtxt"])
def test_random_bytes_never_cause_a_server_error(
    client: TestClient, settings: Settings, suffix: str
) -> None:
    rng = np.random.default_rng(len(suffix))
    for size in (1, 64, 4096):
        content = rng.integers(0, 256, size, dtype=np.uint8).tobytes()
        response = client.post("/api/v1/takes", files={"file": (f"noise{suffix}", content)})
        assert 400 <= response.status_code < 500, (size, response.text)
    stored_nothing(client, settings)
