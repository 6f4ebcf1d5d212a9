"""Runs with options, results, point windows, reviews, the filter registry and the stream."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.filters.apply import filter_keypoints
from mocapqa.io.bvh import read_bvh
from mocapqa.io.formats import read_take
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.render.service import RenderService

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]
TRC_TAKE = (
    "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
)


@pytest.fixture
def analysed(
    client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> dict[str, Any]:
    """The CMU walk, uploaded and analysed."""
    created = upload(client, cmu_walk)
    assert wait_for_run(client, created["run_id"])["status"] == "done"
    return created


def test_rerun_with_other_options_keeps_earlier_runs(
    client: TestClient, analysed: dict[str, Any], wait_for_run: Waiter, cmu_walk: Path
) -> None:
    options = {"checks": ["twist", "filter"], "filter_method": "quat-pd", "max_points": 100}
    response = client.post(f"/api/v1/takes/{analysed['id']}/runs", json=options)
    assert response.status_code == 201, response.text
    run = wait_for_run(client, response.json()["id"])
    assert run["status"] == "done", run["error"]
    assert run["options"]["filter_method"] == "quat-pd"
    result = client.get(f"/api/v1/runs/{run['id']}/result").json()
    assert result["steps"]["filter"]["state"] == "done"
    assert result["steps"]["limits"]["state"] == "skipped"
    assert 50 < len(result["series"]["frames"]) <= 100
    detail = client.get(f"/api/v1/takes/{analysed['id']}").json()
    assert [r["id"] for r in detail["runs"]] == [analysed["run_id"], run["id"]]
    filtered = client.get(f"/api/v1/runs/{run['id']}/download/bvh").content
    first = client.get(f"/api/v1/runs/{analysed['run_id']}/download/bvh").content
    assert filtered != first


def test_bad_run_options_are_refused(client: TestClient, analysed: dict[str, Any]) -> None:
    bad_options: list[dict[str, Any]] = [
        {"checks": ["spelling"]},
        {"twist_method": "magic"},
        {"max_points": 1},
        {"unknown": 1},
        {"checks": ["filter"], "filter_method": "no-such-filter"},
    ]
    for options in bad_options:
        response = client.post(f"/api/v1/takes/{analysed['id']}/runs", json=options)
        assert response.status_code == 422, options
    detail = client.get(f"/api/v1/takes/{analysed['id']}").json()
    assert len(detail["runs"]) == 1


def test_frames_come_in_windows_matching_forward_kinematics(
    client: TestClient, analysed: dict[str, Any], cmu_walk: Path
) -> None:
    run_id = analysed["run_id"]
    window = client.get(f"/api/v1/runs/{run_id}/frames?start=100&stop=110").json()
    assert window["frames"] == list(range(100, 110))
    quats, positions = forward_kinematics(read_bvh(cmu_walk))
    raw = np.asarray(window["raw"])
    np.testing.assert_allclose(raw[:, :31], positions[100:110], atol=2e-3)
    # World rotations orient the drawn bones (half precision, rounded to 3 decimals).
    rotations = np.asarray(window["raw_rotations"])
    assert rotations.shape == (10, raw.shape[1], 4)
    same_sign = np.sign(np.sum(rotations[:, :31] * quats[100:110], axis=-1, keepdims=True))
    np.testing.assert_allclose(rotations[:, :31] * same_sign, quats[100:110], atol=3e-3)
    assert np.asarray(window["corrected_rotations"]).shape == rotations.shape
    overview = client.get(f"/api/v1/runs/{run_id}/frames?max_frames=50").json()
    assert len(overview["frames"]) <= 50
    assert overview["step"] == 11
    bad = client.get(f"/api/v1/runs/{run_id}/frames?start=600")
    assert bad.status_code == 422


def unpack_frames(body: bytes) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Read ``/frames.f32``: a uint32 length, a JSON header, then float32 arrays."""
    length = int(np.frombuffer(body[:4], "<u4")[0])
    header = json.loads(body[4 : 4 + length])
    assert (4 + length) % 4 == 0
    offset, arrays = 4 + length, {}
    for name, components in header["arrays"]:
        shape = (header["count"], header["points"], components)
        size = int(np.prod(shape))
        arrays[name] = np.frombuffer(body, "<f4", size, offset).reshape(shape)
        offset += 4 * size
    assert offset == len(body)
    return header, arrays


def test_packed_frames_hold_the_same_window_as_json(
    client: TestClient, analysed: dict[str, Any]
) -> None:
    run_id = analysed["run_id"]
    for query in ("start=100&stop=110", "max_frames=50", "start=7&step=3&stop=40"):
        window = client.get(f"/api/v1/runs/{run_id}/frames?{query}").json()
        packed = client.get(f"/api/v1/runs/{run_id}/frames.f32?{query}")
        assert packed.status_code == 200
        assert packed.headers["content-type"] == "application/octet-stream"
        header, arrays = unpack_frames(packed.content)
        frames = [header["start"] + k * header["step"] for k in range(header["count"])]
        assert frames == window["frames"]
        assert header["n_frames"] == window["n_frames"]
        assert [name for name, _ in header["arrays"]] == [
            "raw",
            "corrected",
            "raw_rotations",
            "corrected_rotations",
        ]
        for name, values in arrays.items():
            np.testing.assert_allclose(values, np.asarray(window[name]), atol=6e-4)
    # Bad windows are refused as for JSON, naming the problem.
    bad = client.get(f"/api/v1/runs/{run_id}/frames.f32?start=600")
    assert bad.status_code == 422
    assert "start" in bad.json()["detail"]
    assert client.get(f"/api/v1/runs/{run_id}/frames.f32?step=0").status_code == 422
    assert client.get("/api/v1/runs/0123456789abcdef0123456789abcdef/frames.f32").status_code == 404


def test_packed_frames_of_a_keypoint_take_carry_confidence(
    client: TestClient, corpus_dir: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(client, corpus_dir / TRC_TAKE)
    run = wait_for_run(client, created["run_id"])
    assert run["status"] == "done"
    window = client.get(f"/api/v1/runs/{run['id']}/frames?max_frames=40").json()
    _, arrays = unpack_frames(
        client.get(f"/api/v1/runs/{run['id']}/frames.f32?max_frames=40").content
    )
    assert "confidence" in arrays
    for name, values in arrays.items():
        expected = np.array(window[name], dtype=float)  # JSON null -> NaN
        values = values.reshape(expected.shape)  # per-point marks: one component
        np.testing.assert_array_equal(np.isnan(values), np.isnan(expected))
        np.testing.assert_allclose(values, expected, atol=6e-3, equal_nan=True)


def test_unfinished_runs_answer_409(client: TestClient, analysed: dict[str, Any]) -> None:
    services = client.app.state.services  # type: ignore[attr-defined]
    run_id = services.repository.add_run(analysed["id"], {})
    assert client.get(f"/api/v1/runs/{run_id}/result").status_code == 409
    assert client.get(f"/api/v1/runs/{run_id}/download/bvh").status_code == 409
    assert client.get(f"/api/v1/runs/{run_id}").json()["status"] == "queued"


def test_reviews_are_history_and_filter_the_list(
    client: TestClient, analysed: dict[str, Any]
) -> None:
    take_id = analysed["id"]
    first = {"status": "needs_fix", "notes": "left arm", "reviewer": "ann"}
    assert client.post(f"/api/v1/takes/{take_id}/reviews", json=first).status_code == 201
    second = {"status": "approved", "notes": "fixed", "reviewer": "bob"}
    assert client.post(f"/api/v1/takes/{take_id}/reviews", json=second).status_code == 201
    history = client.get(f"/api/v1/takes/{take_id}/reviews").json()
    assert [h["status"] for h in history] == ["approved", "needs_fix"]
    assert client.get("/api/v1/takes?review_status=approved").json()["total"] == 1
    assert client.get("/api/v1/takes?review_status=rejected").json()["total"] == 0
    bad = client.post(f"/api/v1/takes/{take_id}/reviews", json={"status": "great"})
    assert bad.status_code == 422
    assert client.get("/api/v1/takes?status=bogus").status_code == 422


def test_filter_registry_lists_parameters_with_units(client: TestClient) -> None:
    filters = {f["name"]: f for f in client.get("/api/v1/filters").json()}
    assert {"adaptive", "kalman", "one-euro", "ema"} <= set(filters)
    one_euro = {p["name"]: p for p in filters["one-euro"]["parameters"]}
    assert one_euro["min_cutoff_hz"]["unit"] == "Hz"
    assert "keypoints" in filters["adaptive"]["applies_to"]
    # The declared ranges, so the re-run form refuses a value before sending it.
    assert (one_euro["min_cutoff_hz"]["minimum"], one_euro["min_cutoff_hz"]["maximum"]) == (
        0.001,
        10_000.0,
    )
    ema = {p["name"]: p for p in filters["ema"]["parameters"]}
    assert ema["time_constant_s"]["maximum"] == 60.0
    kalman = {p["name"]: p for p in filters["kalman"]["parameters"]}
    # min_confidence is below 1: the bound is served as excluded, as the server refuses it.
    assert kalman["min_confidence"]["maximum"] == 1.0
    assert kalman["min_confidence"]["maximum_excluded"] is True
    assert kalman["min_confidence"]["minimum_excluded"] is False
    for entry in filters.values():
        for parameter in entry["parameters"]:
            if parameter["type"] == "float":
                assert parameter["minimum"] is not None, (entry["name"], parameter["name"])


def test_stream_filters_frames_and_returns_weights(client: TestClient) -> None:
    rng = np.random.default_rng(3)
    with client.websocket_connect("/api/v1/stream/filter") as socket:
        socket.send_json({"fps": 30, "n_keypoints": 4})
        assert socket.receive_json()["ready"] is True
        for i in range(10):
            frame = (np.ones((4, 3)) + 0.01 * rng.standard_normal((4, 3))).tolist()
            socket.send_json({"positions": frame, "confidence": [1.0] * 4})
            answer = socket.receive_json()
            assert answer["frame"] == i
            assert np.asarray(answer["positions"]).shape == (4, 3)
            total = sum(answer["weights"][k]["mean"] for k in ("kalman", "one_euro", "ema"))
            assert total == pytest.approx(1.0, abs=1e-3)
        socket.send_json({"positions": [[1, 2]]})
        assert "Expected positions" in socket.receive_json()["error"]


def test_stream_in_metres_matches_the_batch_default_preset(
    client: TestClient, corpus_dir: Path
) -> None:
    trc = corpus_dir / "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d"
    take = read_take(trc / "S00_P00_T01_BalancingTrial_0-100.trc")
    assert isinstance(take, KeypointSequence)
    positions = take.positions[:40].copy()
    positions[5:9, 3] = np.nan  # a keypoint lost for four frames is sent as null
    seq = dataclasses.replace(take, positions=positions, confidence=take.confidence[:40])
    batch = filter_keypoints(seq, method="adaptive", preset="default").sequence.positions
    streamed = []
    with client.websocket_connect("/api/v1/stream/filter") as socket:
        socket.send_json({"fps": seq.fps, "n_keypoints": seq.n_keypoints, "length_unit": "m"})
        ready = socket.receive_json()
        assert ready["length_unit"] == "m"
        assert ready["preset"] == "default"
        for frame in seq.positions:
            cells = [[None if np.isnan(v) else float(v) for v in row] for row in frame]
            socket.send_json({"positions": cells})
            streamed.append(socket.receive_json()["positions"])
    streamed_positions = np.asarray(streamed, dtype=np.float64)
    # The stream is causal: it agrees with the batch filter up to the keypoint's gap. Over the
    # gap the batch filter, which sees the frames after it, interpolates between the filtered
    # samples on either side instead of carrying a prediction (and so differs after it).
    others = np.arange(seq.n_keypoints) != 3
    np.testing.assert_allclose(streamed_positions[:, others], batch[:, others], atol=6e-6)
    np.testing.assert_allclose(streamed_positions[:5, 3], batch[:5, 3], atol=6e-6)
    ramp = np.linspace(0.0, 1.0, 6)[1:-1, None]
    np.testing.assert_allclose(batch[5:9, 3], batch[4, 3] + ramp * (batch[9, 3] - batch[4, 3]))


def test_stream_refuses_a_bad_opening(client: TestClient) -> None:
    with client.websocket_connect("/api/v1/stream/filter") as socket:
        socket.send_json({"fps": "fast"})
        assert "Expected a number" in socket.receive_json()["error"]


def test_runs_left_by_a_stopped_server_finish_after_restart(
    settings: Settings,
    cmu_walk: Path,
    wait_for_run: Waiter,
    upload: Uploader,
    renderer: RenderService,
) -> None:
    with TestClient(create_app(settings, renderer=renderer)) as client:
        created = upload(client, cmu_walk)
        wait_for_run(client, created["run_id"])
        services = client.app.state.services  # type: ignore[attr-defined]
        orphan = services.repository.add_run(created["id"], {})
        services.repository.mark_running(orphan)  # as if the server died mid-run
    with TestClient(create_app(settings, renderer=renderer)) as client:
        run = wait_for_run(client, orphan)
        assert run["status"] == "done"
        assert client.get(f"/api/v1/runs/{orphan}/download/bvh").status_code == 200


def test_frontend_and_plotly_are_served(client: TestClient) -> None:
    page = client.get("/")
    assert page.status_code == 200
    assert "/vendor/plotly-" in page.text
    # Plotly's address is in a <meta>: the views that draw charts load it on demand.
    script = page.text.split('name="plotly-src" content="')[1].split('"')[0]
    plotly = client.get(script, headers={"Accept-Encoding": "gzip"})
    assert plotly.status_code == 200
    assert plotly.headers["content-encoding"] == "gzip"
    for path in (
        "/static/js/app.js",
        "/static/js/api.js",
        "/static/js/charts.js",
        "/static/js/scene3d.js",
    ):
        assert client.get(path).status_code == 200
    assert client.get("/docs").status_code == 200


def test_twist_apply_choice_decides_the_corrected_take(
    client: TestClient, corpus_dir: Path, tmp_path: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    from mocapqa.io.bvh_write import write_bvh
    from mocapqa.twist.inject import inject_twist_errors

    motion = read_bvh(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    corrupted, truth = inject_twist_errors(motion, np.random.default_rng(2))
    path = tmp_path / "corrupted.bvh"
    write_bvh(path, corrupted)
    created = upload(client, path)
    assert wait_for_run(client, created["run_id"])["status"] == "done"
    results = {}
    for apply in ("none", "all", "0"):
        response = client.post(
            f"/api/v1/takes/{created['id']}/runs", json={"checks": ["twist"], "twist_apply": apply}
        )
        assert response.status_code == 201, response.text
        run = wait_for_run(client, response.json()["id"])
        assert run["status"] == "done", run["error"]
        assert run["options"]["twist_apply"] == apply
        result = client.get(f"/api/v1/runs/{run['id']}/result").json()
        twist = [f for f in result["findings"] if f["kind"] == "twist"]
        assert len(twist) >= len({i.joint for i in truth.intervals})
        assert [f["id"] for f in twist] == list(range(len(twist)))
        results[apply] = (twist, client.get(f"/api/v1/runs/{run['id']}/download/bvh").content)
    assert not any(f["applied"] for f in results["none"][0])
    assert all(f["applied"] for f in results["all"][0])
    assert [f["applied"] for f in results["0"][0]] == [True] + [False] * (len(twist) - 1)
    assert len({results["none"][1], results["all"][1], results["0"][1]}) == 3
    for bad in ("maybe", "-1", "0,x"):
        response = client.post(
            f"/api/v1/takes/{created['id']}/runs", json={"checks": ["twist"], "twist_apply": bad}
        )
        assert response.status_code == 422, bad
    # Ids the take's newest twist run does not list are refused before a run is queued,
    # naming the option and the ids that run has.
    runs_before = len(client.get(f"/api/v1/takes/{created['id']}").json()["runs"])
    for unknown in (f"0,{len(twist)}", "0,99999999999999999999999"):
        response = client.post(f"/api/v1/takes/{created['id']}/runs", json={"twist_apply": unknown})
        assert response.status_code == 422, unknown
        assert response.json()["field"] == "twist_apply"
        assert f"0 to {len(twist) - 1}" in response.json()["detail"]
    assert len(client.get(f"/api/v1/takes/{created['id']}").json()["runs"]) == runs_before


def test_twist_apply_ids_need_a_finished_twist_run(
    client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    # The clean walk's runs list no twist interval, so there are no ids to name.
    created = upload(client, cmu_walk)
    take = created["id"]
    only_limits = client.post(f"/api/v1/takes/{take}/runs", json={"checks": ["limits"]})
    assert only_limits.status_code == 201
    for run_id in (created["run_id"], only_limits.json()["id"]):
        assert wait_for_run(client, run_id)["status"] == "done"
    findings = client.get(f"/api/v1/runs/{created['run_id']}/result").json()["findings"]
    assert not [f for f in findings if f["kind"] == "twist"]
    response = client.post(f"/api/v1/takes/{take}/runs", json={"twist_apply": "0"})
    assert response.status_code == 422, response.text
    assert response.json()["field"] == "twist_apply"
    assert "no finished run with twist intervals" in response.json()["detail"]
    named = client.post(f"/api/v1/takes/{take}/runs", json={"twist_apply": "none"})
    assert named.status_code == 201, named.text
