"""Frame windows within their value budget, and the fields the review's 422 answers name.

``/frames`` and ``/frames.f32`` grow the step until a window fits both ``max_frames`` and
:data:`~mocapqa.api.frame_windows.MAX_WINDOW_VALUES`; a window outside the take names
``start`` or ``stop``; an upload part with no file name and a keypoint CSV confidence
outside 0–1 name their field.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from tests.api.test_runs import unpack_frames

from mocapqa.api import frame_windows
from mocapqa.api.frame_windows import MAX_WINDOW_VALUES

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]
REPEATS = 20
"""Copies of the CMU walk's frames in the long take (10,480 frames × 31 joints)."""


def values_of(header: dict[str, Any]) -> int:
    """Values (frames × points × components over every array) a packed window holds."""
    return int(header["count"] * header["points"] * sum(c for _, c in header["arrays"]))


def done_run(client: TestClient, created: dict[str, Any], wait_for_run: Waiter) -> str:
    run = wait_for_run(client, created["run_id"])
    assert run["status"] == "done", run.get("error")
    return str(run["id"])


@pytest.fixture
def long_walk(tmp_path: Path, cmu_walk: Path) -> Path:
    """The CMU walk with its frames repeated :data:`REPEATS` times."""
    lines = cmu_walk.read_text().splitlines()
    at = next(k for k, line in enumerate(lines) if line.startswith("Frames:"))
    motion = [line for line in lines[at + 2 :] if line.strip()]
    head = [*lines[:at], f"Frames: {len(motion) * REPEATS}", lines[at + 1]]
    path = tmp_path / "long_walk.bvh"
    path.write_text("\n".join(head + motion * REPEATS) + "\n")
    return path


def test_a_long_take_is_served_whole_with_a_grown_step(
    client: TestClient, long_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    """The review's case: 20,000 frames asked of a 10,480-frame, 31-joint take was a 422."""
    run_id = done_run(client, upload(client, long_walk), wait_for_run)
    answer = client.get(f"/api/v1/runs/{run_id}/frames.f32?max_frames=20000")
    assert answer.status_code == 200, answer.text
    header, arrays = unpack_frames(answer.content)
    n_frames = header["n_frames"]
    assert n_frames == 524 * REPEATS
    per_frame = values_of(header) // header["count"]
    assert per_frame * n_frames > MAX_WINDOW_VALUES  # the whole take at step 1 does not fit
    assert values_of(header) <= MAX_WINDOW_VALUES
    assert header["step"] == -(-n_frames // (MAX_WINDOW_VALUES // per_frame))
    assert header["start"] == 0
    assert header["count"] == len(range(0, n_frames, header["step"]))
    # The rows picked from the stored arrays are those of the frames named: a full-rate
    # window of ten frames holds the same values at the frames both hold.
    near_end = n_frames - 20
    _, fine = unpack_frames(
        client.get(f"/api/v1/runs/{run_id}/frames.f32?start={near_end}&stop={n_frames}").content
    )
    shared = [k for k in range(near_end, n_frames) if k % header["step"] == 0]
    for name, values in arrays.items():
        coarse = values[[k // header["step"] for k in shared]]
        np.testing.assert_array_equal(coarse, fine[name][[k - near_end for k in shared]])
    window = client.get(f"/api/v1/runs/{run_id}/frames?max_frames=20000")
    assert window.status_code == 200, window.text
    assert window.json()["step"] == header["step"]
    overview = client.get(f"/api/v1/runs/{run_id}/frames.f32?max_frames=800")
    assert unpack_frames(overview.content)[0]["step"] == -(-n_frames // 800)


def test_a_take_of_many_keypoints_is_served_with_a_grown_step(
    client: TestClient, wait_for_run: Waiter
) -> None:
    """The dashboard's 800-frame overview of 1,000 keypoints (8,000 values a frame)."""
    rng = np.random.default_rng(7)
    drift = np.cumsum(rng.normal(scale=1e-3, size=(400, 1000, 3)), axis=0)
    points = (drift + rng.normal(size=(1, 1000, 3))).astype(np.float32)
    stored = io.BytesIO()
    np.save(stored, points)
    response = client.post(
        "/api/v1/takes",
        files={"file": ("many.npy", stored.getvalue())},
        data={"fps": "30", "length_unit": "m"},
    )
    assert response.status_code == 201, response.text
    run_id = done_run(client, response.json(), wait_for_run)
    answer = client.get(f"/api/v1/runs/{run_id}/frames.f32?max_frames=800")
    assert answer.status_code == 200, answer.text
    header, arrays = unpack_frames(answer.content)
    assert values_of(header) <= MAX_WINDOW_VALUES
    assert (header["step"], header["count"]) == (2, 200)
    np.testing.assert_array_equal(arrays["raw"], points[::2])


def test_a_frame_alone_over_the_budget_is_refused_naming_max_frames(
    client: TestClient,
    cmu_walk: Path,
    upload: Uploader,
    wait_for_run: Waiter,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    run_id = done_run(client, upload(client, cmu_walk), wait_for_run)
    header, _ = unpack_frames(client.get(f"/api/v1/runs/{run_id}/frames.f32?stop=1").content)
    per_frame = values_of(header)
    monkeypatch.setattr(frame_windows, "MAX_WINDOW_VALUES", per_frame * 5)
    header, _ = unpack_frames(client.get(f"/api/v1/runs/{run_id}/frames.f32?start=3").content)
    assert header["count"] == 5
    assert header["step"] == -(-(header["n_frames"] - 3) // 5)
    monkeypatch.setattr(frame_windows, "MAX_WINDOW_VALUES", per_frame - 1)
    for route in ("frames", "frames.f32"):
        refused = client.get(f"/api/v1/runs/{run_id}/{route}?max_frames=1")
        assert refused.status_code == 422, refused.text
        assert refused.json()["field"] == "max_frames"
        assert str(per_frame) in refused.json()["detail"]


@pytest.mark.parametrize(
    ("query", "field"),
    [
        ("start=100000", "start"),
        ("start=524", "start"),
        ("start=100&stop=50", "stop"),
        ("start=100&stop=100", "stop"),
    ],
)
def test_a_window_outside_the_take_names_the_field(
    query: str,
    field: str,
    client: TestClient,
    cmu_walk: Path,
    upload: Uploader,
    wait_for_run: Waiter,
) -> None:
    run_id = done_run(client, upload(client, cmu_walk), wait_for_run)
    for route in ("frames", "frames.f32"):
        refused = client.get(f"/api/v1/runs/{run_id}/{route}?{query}")
        assert refused.status_code == 422, refused.text
        assert refused.json()["field"] == field
        assert refused.json()["detail"].startswith(f"{field}: Expected")
    last = client.get(f"/api/v1/runs/{run_id}/frames?start=523&stop=100000").json()
    assert last["frames"] == [523]


@pytest.mark.parametrize(
    "disposition",
    [
        'form-data; name="file"',
        "form-data; name=\"file\"; filename*=UTF-8''t%C3%A9.bvh",
    ],
)
def test_an_upload_part_without_a_file_name_is_422_naming_the_file(
    disposition: str, client: TestClient, cmu_walk: Path
) -> None:
    body = (
        f"--edge\r\nContent-Disposition: {disposition}\r\n"
        "Content-Type: application/octet-stream\r\n\r\n"
    ).encode()
    body += cmu_walk.read_bytes() + b"\r\n--edge--\r\n"
    refused = client.post(
        "/api/v1/takes",
        content=body,
        headers={"content-type": "multipart/form-data; boundary=edge"},
    )
    assert refused.status_code == 422, refused.text
    assert refused.json()["field"] == "body.file"
    assert "without one" in refused.json()["detail"]
    assert "UploadFile" not in refused.text
    # A client that leaves an empty name out sends the same part.
    empty = client.post("/api/v1/takes", files={"file": ("", cmu_walk.read_bytes())})
    assert empty.status_code == 422
    assert empty.json()["field"] == "body.file"
    assert client.get("/api/v1/takes").json()["total"] == 0


@pytest.mark.parametrize("confidence", ["2", "-1", "nan"])
def test_a_keypoint_csv_confidence_outside_0_to_1_names_the_column(
    confidence: str, client: TestClient
) -> None:
    rows = ["frame,keypoint,x,y,z,confidence", "0,nose,0.1,0.2,0.3,0.9"]
    rows.append(f"1,nose,0.1,0.2,0.3,{confidence}")
    refused = client.post(
        "/api/v1/takes",
        files={"file": ("take.csv", "\n".join(rows).encode())},
        data={"fps": "30"},
    )
    assert refused.status_code == 422, refused.text
    assert (refused.json()["line"], refused.json()["field"]) == (3, "confidence")
