"""Accept / reject per swap of a marker take: history, the decided C3D, errors."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from mocapqa.io.c3d import MarkerTake, read_c3d, write_c3d

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]

SOURCE = Path("c3d/optitrack/kinematics_tennis_serve.c3d")
SWAPS = (("Derrick:LBHD", "Derrick:LFHD", 400, 429), ("Derrick:LASI", "Derrick:LPSI", 700, 729))
"""The injected swaps: two markers of one segment exchanged over 30 frames, ends inclusive."""


def exchanged(take: MarkerTake, swaps: tuple[tuple[str, str, int, int], ...]) -> MarkerTake:
    """``take`` with each swap's two labels' samples (positions and residuals) exchanged."""
    positions, residuals = take.points.positions.copy(), take.residuals.copy()
    names = list(take.points.names)
    for a, b, start, end in swaps:
        pair, frames = [names.index(a), names.index(b)], slice(start, end + 1)
        positions[frames, pair] = positions[frames, pair[::-1]]
        residuals[frames, pair] = residuals[frames, pair[::-1]]
    return replace(take, points=replace(take.points, positions=positions), residuals=residuals)


@pytest.fixture
def swapped(corpus_dir: Path, tmp_path: Path) -> Path:
    """The tennis serve (no gaps, no swaps) with :data:`SWAPS` injected."""
    source = corpus_dir / SOURCE
    path = tmp_path / "tennis_serve_swapped.c3d"
    write_c3d(path, exchanged(read_c3d(source), SWAPS), source=source)
    return path


@pytest.fixture
def swap_run(
    client: TestClient, swapped: Path, upload: Uploader, wait_for_run: Waiter
) -> dict[str, Any]:
    """The swapped take uploaded and checked with the default options."""
    done = wait_for_run(client, upload(client, swapped)["run_id"])
    assert done["status"] == "done", done["error"]
    return done


def take_files(client: TestClient, take_id: str) -> dict[str, str]:
    """The take's stored files by name, as content hashes."""
    folder = client.app.state.services.files.take_dir(take_id)  # type: ignore[attr-defined]
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir()}


def decide(client: TestClient, run_id: str, swap: int, decision: str, note: str = "") -> Any:
    response = client.post(
        f"/api/v1/runs/{run_id}/swaps/{swap}/decisions", json={"decision": decision, "note": note}
    )
    assert response.status_code == 201, response.text
    return response.json()


def decided_positions(client: TestClient, run_id: str, tmp_path: Path) -> np.ndarray:
    response = client.get(f"/api/v1/runs/{run_id}/decisions/c3d")
    assert response.status_code == 200, response.text
    assert "decided.c3d" in response.headers["content-disposition"]
    path = tmp_path / "decided.c3d"
    path.write_bytes(response.content)
    return read_c3d(path).points.positions


def test_swap_decisions_are_history_and_the_download_repairs_exactly_the_accepted(
    client: TestClient, corpus_dir: Path, swapped: Path, swap_run: dict[str, Any], tmp_path: Path
) -> None:
    run_id, take_id = swap_run["id"], swap_run["take_id"]
    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    assert body["item"] == "swap"
    assert body["intervals"] == []
    assert body["history"] == []
    swaps = body["swaps"]
    found = [(*s["markers"], s["start_frame"], s["end_frame"]) for s in swaps]
    assert found == list(SWAPS)
    assert all(s["applied"] and s["corrected"] and s["decision"] is None for s in swaps)
    assert all(s["confidence"] >= 0.8 for s in swaps)
    # The ids are the findings' ids of the run.
    result = client.get(f"/api/v1/runs/{run_id}/result").json()
    listed = {f["id"]: f["markers"] for f in result["findings"] if f["kind"] == "swap"}
    assert listed == {s["id"]: s["markers"] for s in swaps}

    # Decisions change the decided download only.
    stored = client.get(f"/api/v1/runs/{run_id}/download/c3d").content
    raw = take_files(client, take_id)

    clean = read_c3d(corpus_dir / SOURCE).points.positions
    injected = read_c3d(swapped).points.positions
    # Undecided: both follow the run (repaired), as its own corrected take has them.
    np.testing.assert_array_equal(decided_positions(client, run_id, tmp_path), clean)

    first, second = swaps[0]["id"], swaps[1]["id"]
    decide(client, run_id, first, "reject", "first look")
    decide(client, run_id, second, "reject")
    last = decide(client, run_id, first, "accept", "labels are exchanged")
    assert last["item"] == "swap"
    assert last["interval_id"] == first
    assert last["reviewer"] == "anonymous"
    assert last["client"] == "testclient"

    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    assert [(h["interval_id"], h["decision"]) for h in body["history"]] == [
        (first, "accept"),
        (second, "reject"),
        (first, "reject"),
    ]
    assert {h["item"] for h in body["history"]} == {"swap"}
    assert body["history"][0]["note"] == "labels are exchanged"
    by_id = {s["id"]: s for s in body["swaps"]}
    assert by_id[first]["decision"] == "accept"
    assert by_id[first]["corrected"]
    assert by_id[second]["decision"] == "reject"
    assert not by_id[second]["corrected"]

    # The accepted swap repaired, the rejected one left as recorded, nothing else changed.
    a, b, start, end = SWAPS[1]
    names = list(read_c3d(swapped).points.names)
    pair, frames = [names.index(a), names.index(b)], slice(start, end + 1)
    expected = clean.copy()
    expected[frames, pair] = injected[frames, pair]
    np.testing.assert_array_equal(decided_positions(client, run_id, tmp_path), expected)

    decide(client, run_id, first, "reject")
    np.testing.assert_array_equal(decided_positions(client, run_id, tmp_path), injected)

    # Once the take is approved its decisions are closed: a further one is a 409 and the
    # decided download stays as it was.
    approved = client.post(f"/api/v1/takes/{take_id}/reviews", json={"status": "approved"})
    assert approved.status_code == 201, approved.text
    refused = client.post(
        f"/api/v1/runs/{run_id}/swaps/{first}/decisions", json={"decision": "accept"}
    )
    assert refused.status_code == 409, refused.text
    assert "approved" in refused.json()["detail"]
    np.testing.assert_array_equal(decided_positions(client, run_id, tmp_path), injected)

    # The approved take, its file and the run's own corrected C3D are as they were.
    reviews = client.get(f"/api/v1/takes/{take_id}/reviews").json()
    assert [r["status"] for r in reviews] == ["approved"]
    assert client.get(f"/api/v1/runs/{run_id}/download/c3d").content == stored
    assert take_files(client, take_id) == raw


def test_swap_decision_errors_name_the_problem(
    client: TestClient,
    corpus_dir: Path,
    swap_run: dict[str, Any],
    upload: Uploader,
    wait_for_run: Waiter,
) -> None:
    run_id = swap_run["id"]
    url = f"/api/v1/runs/{run_id}"
    assert client.post(f"{url}/swaps/2/decisions", json={"decision": "accept"}).status_code == 404
    bad = client.post(f"{url}/swaps/0/decisions", json={"decision": "maybe"})
    assert bad.status_code == 422
    # A marker run has swaps, not twist intervals, and no decided BVH.
    for answer in (
        client.post(f"{url}/intervals/0/decisions", json={"decision": "accept"}),
        client.get(f"{url}/decisions/bvh"),
    ):
        assert answer.status_code == 409
        assert "swaps" in answer.json()["detail"]

    # Swaps the check no longer finds as the run listed them are not repaired by id.
    report_path = client.app.state.services.files.run_dir(run_id) / "report.json"  # type: ignore[attr-defined]
    report = json.loads(report_path.read_text())
    for finding in report["findings"]:
        if finding["kind"] == "swap":
            finding["start_frame"] += 1
    report_path.write_text(json.dumps(report) + " ")  # another size: read again
    answer = client.get(f"{url}/decisions/c3d")
    assert answer.status_code == 409
    assert "start a new run" in answer.json()["detail"]

    # A motion run has twist intervals, not swaps, and no decided C3D: its download is BVH.
    bvh = upload(client, corpus_dir / "bvh" / "cmu" / "iclone" / "005_05.bvh")
    motion_id = bvh["run_id"]
    assert wait_for_run(client, motion_id)["status"] == "done"
    for answer in (
        client.post(f"/api/v1/runs/{motion_id}/swaps/0/decisions", json={"decision": "accept"}),
        client.get(f"/api/v1/runs/{motion_id}/decisions/c3d"),
    ):
        assert answer.status_code == 409
        assert "motion take" in answer.json()["detail"]
        assert "/decisions/bvh" in answer.json()["detail"]

    # A marker run without the markers check has nothing to decide.
    filtered = client.post(
        f"/api/v1/takes/{swap_run['take_id']}/runs", json={"checks": ["filter"]}
    ).json()
    assert wait_for_run(client, filtered["id"])["status"] == "done"
    answer = client.get(f"/api/v1/runs/{filtered['id']}/decisions")
    assert answer.status_code == 409
    assert "markers check" in answer.json()["detail"]


def test_undecided_the_decided_c3d_is_the_runs_corrected_take_gaps_filled_alike(
    client: TestClient, corpus_dir: Path, upload: Uploader, wait_for_run: Waiter, tmp_path: Path
) -> None:
    gapped = corpus_dir / "c3d/optitrack/kinematics_tennis_serve_nan.c3d"
    run = wait_for_run(client, upload(client, gapped)["run_id"])
    assert run["status"] == "done", run["error"]
    corrected = tmp_path / "corrected.c3d"
    corrected.write_bytes(client.get(f"/api/v1/runs/{run['id']}/download/c3d").content)
    ours, decided = read_c3d(corrected), decided_positions(client, run["id"], tmp_path)
    raw = read_c3d(gapped).points.positions
    assert np.isnan(raw).any()
    assert (np.isnan(raw) & ~np.isnan(decided)).any()  # some gaps filled
    np.testing.assert_array_equal(decided, ours.points.positions)


def test_an_accepted_foot_lock_pins_that_foots_markers_only(
    client: TestClient, swap_run: dict[str, Any], tmp_path: Path
) -> None:
    """The decided C3D pins the foot markers of each accepted foot lock (a skate finding of the
    feet step) after the swaps; undecided locks are not applied (tests/api/test_feet_decisions.py
    for BVH takes)."""
    from tests.api.test_feet_decisions import decide_lock

    from mocapqa.feet.markers import marker_label

    run_id = swap_run["id"]
    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    locks = body["locks"]
    assert locks
    assert all(lock["decision"] is None and not lock["applied"] for lock in locks)
    before = decided_positions(client, run_id, tmp_path)
    lock = locks[0]
    decide_lock(client, run_id, lock["id"], "accept")
    after = decided_positions(client, run_id, tmp_path)
    names = [marker_label(n) for n in read_c3d(tmp_path / "decided.c3d").points.names]
    moved = np.nan_to_num(np.abs(after - before)).max(axis=(0, 2)) > 0
    side = lock["foot"][0].upper()
    assert moved.any()
    # The foot's heel, toe and ankle markers move together; no other marker does.
    assert {names[m] for m in np.flatnonzero(moved)} == {f"{side}HEE", f"{side}TOE", f"{side}ANK"}
    assert lock["joint"].endswith(f"{side}HEE")
    # Horizontally only (one axis, the up axis, keeps every value), on the contact and its blends.
    axes = np.nan_to_num(np.abs(after - before)).max(axis=(0, 1)) > 0
    assert axes.sum() == 2
    frames = np.flatnonzero(np.nan_to_num(np.abs(after - before)).max(axis=(1, 2)) > 0)
    assert frames.min() >= lock["start_frame"] - 10
    assert frames.max() <= lock["end_frame"] + 10
    decide_lock(client, run_id, lock["id"], "reject")
    np.testing.assert_array_equal(decided_positions(client, run_id, tmp_path), before)


def test_a_c3d_takes_decided_take_is_also_served_as_trc(
    client: TestClient, swap_run: dict[str, Any], tmp_path: Path
) -> None:
    """For OpenSim: the decided C3D's markers, names, rate and unit as TRC, decided alike."""
    from mocapqa.io.trc import parse_trc

    run_id = swap_run["id"]

    def both() -> tuple[np.ndarray, Any]:
        response = client.get(f"/api/v1/runs/{run_id}/decisions/trc")
        assert response.status_code == 200, response.text
        assert "decided.trc" in response.headers["content-disposition"]
        return decided_positions(client, run_id, tmp_path), parse_trc(response.content)

    c3d, trc = both()
    points = read_c3d(tmp_path / "decided.c3d").points
    assert (trc.names, trc.fps, trc.length_unit) == (points.names, points.fps, points.length_unit)
    assert trc.start_frame == points.start_frame  # the C3D's first frame, as OrigDataStartFrame
    np.testing.assert_array_equal(trc.positions, c3d)
    swaps = client.get(f"/api/v1/runs/{run_id}/decisions").json()["swaps"]
    decide(client, run_id, swaps[0]["id"], "reject")
    rejected, trc = both()
    assert not np.array_equal(rejected, c3d, equal_nan=True)
    np.testing.assert_array_equal(trc.positions, rejected)


def test_a_feet_only_run_of_a_c3d_take_gives_the_raw_take_with_its_accepted_locks(
    client: TestClient,
    swapped: Path,
    swap_run: dict[str, Any],
    wait_for_run: Waiter,
    tmp_path: Path,
) -> None:
    """A C3D take's run with the feet check and no markers check: no swap repaired, no gap
    filled; the decided C3D (and its TRC) is the raw take with the accepted locks pinned."""
    from tests.api.test_feet_decisions import decide_lock

    from mocapqa.feet.markers import marker_label
    from mocapqa.io.trc import parse_trc

    response = client.post(f"/api/v1/takes/{swap_run['take_id']}/runs", json={"checks": ["feet"]})
    assert response.status_code in (200, 201, 202), response.text
    run = wait_for_run(client, response.json()["id"])
    assert run["status"] == "done", run["error"]
    run_id = run["id"]
    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    assert (body["item"], body["swaps"]) == ("swap", [])
    locks = body["locks"]
    assert locks

    # No lock accepted: the markers as recorded, the injected swaps left in.
    raw = read_c3d(swapped).points
    undecided = decided_positions(client, run_id, tmp_path)
    np.testing.assert_array_equal(undecided, raw.positions)
    trc = client.get(f"/api/v1/runs/{run_id}/decisions/trc")
    assert trc.status_code == 200, trc.text
    np.testing.assert_array_equal(parse_trc(trc.content).positions, raw.positions)

    lock = locks[0]
    decide_lock(client, run_id, lock["id"], "accept")
    after = decided_positions(client, run_id, tmp_path)
    change = np.nan_to_num(np.abs(after - undecided))
    names = [marker_label(n) for n in raw.names]
    side = lock["foot"][0].upper()
    moved = {names[m] for m in np.flatnonzero(change.max(axis=(0, 2)) > 0)}
    assert moved == {f"{side}HEE", f"{side}TOE", f"{side}ANK"}
    assert (change.max(axis=(0, 1)) > 0).sum() == 2
    frames = np.flatnonzero(change.max(axis=(1, 2)) > 0)
    assert lock["start_frame"] - 10 <= frames.min() <= frames.max() <= lock["end_frame"] + 10
