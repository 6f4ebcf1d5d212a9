"""The decided TRC of a marker take: exactly the accepted swaps repaired, the run's fills, the
source's header; and its errors."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from datetime import timedelta
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from mocapqa.io.formats import write_keypoints
from mocapqa.io.trc import parse_trc, read_trc, write_trc
from mocapqa.markers.repair import repair_markers
from mocapqa.store.roles import Role

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]

SOURCE = Path(
    "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/"
    "S00_P00_T01_BalancingTrial_0-100_filt_butterworth_LSTM.trc"
)
"""A real Pose2Sim take: 64 markers (21 keypoints and 43 augmented ones), 100 frames at 60 Hz,
in metres, frames numbered from 1, no missing sample and no swap."""
SWAP = ("L_thigh2_study", "L_thigh3_study", 39, 61)
"""The injected swap: two markers of the left thigh exchanged over 23 frames, ends inclusive
(the check finds it with confidence 0.67, below the confident rule: the run leaves it)."""
GAPS = (("r_knee_study", 10, 12), ("RHeel", 80, 82), ("LWrist", 50, 95))
"""The injected gaps, ends inclusive: the first two are filled confidently, the last (0.77 s
of a wrist) is not."""


def injected(corpus_dir: Path) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The source's positions and the positions with :data:`SWAP` and :data:`GAPS`."""
    source = read_trc(corpus_dir / SOURCE)
    names = list(source.names)
    clean = source.positions
    positions = clean.copy()
    a, b, start, end = SWAP
    pair, frames = [names.index(a), names.index(b)], slice(start, end + 1)
    positions[frames, pair] = clean[frames, pair[::-1]]
    for name, first, last in GAPS:
        positions[first : last + 1, names.index(name)] = np.nan
    return clean, positions, names


@pytest.fixture
def swapped(corpus_dir: Path, tmp_path: Path) -> Path:
    """The Pose2Sim take with :data:`SWAP` and :data:`GAPS` injected, written as TRC."""
    source = read_trc(corpus_dir / SOURCE)
    _, positions, _ = injected(corpus_dir)
    path = tmp_path / "balancing_swapped.trc"
    write_trc(path, replace(source, positions=positions))
    return path


@pytest.fixture
def trc_run(
    client: TestClient, swapped: Path, upload: Uploader, wait_for_run: Waiter
) -> dict[str, Any]:
    """The swapped TRC take uploaded and checked with the default options."""
    done = wait_for_run(client, upload(client, swapped)["run_id"])
    assert done["status"] == "done", done["error"]
    return done


def decided_trc(client: TestClient, run_id: str, **headers: str) -> tuple[bytes, np.ndarray]:
    """The decided TRC's bytes and its positions as the project's reader reads them."""
    response = client.get(f"/api/v1/runs/{run_id}/decisions/trc", headers=headers)
    assert response.status_code == 200, response.text
    assert response.headers["content-type"].startswith("text/plain")
    assert ".decided.trc" in response.headers["content-disposition"]
    return response.content, parse_trc(response.content, "decided.trc").positions


def filled_mask(result: dict[str, Any], names: list[str], shape: tuple[int, int]) -> np.ndarray:
    """``(F, M)``: the samples of the gaps the run lists as filled (``gap`` findings)."""
    mask = np.zeros(shape, dtype=bool)
    for finding in result["findings"]:
        if finding["kind"] == "gap":
            first, last = finding["start_frame"], finding["end_frame"]
            mask[first : last + 1, names.index(finding["joint"])] = True
    return mask


def test_the_decided_trc_repairs_exactly_the_accepted_swap_and_fills_as_the_run(
    client: TestClient, corpus_dir: Path, trc_run: dict[str, Any]
) -> None:
    run_id = trc_run["id"]
    clean, raw, names = injected(corpus_dir)
    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    assert body["item"] == "swap"
    [swap] = body["swaps"]
    assert (*swap["markers"], swap["start_frame"], swap["end_frame"]) == SWAP
    assert not swap["applied"]
    result = client.get(f"/api/v1/runs/{run_id}/result").json()
    filled = filled_mask(result, names, raw.shape[:2])
    assert {f["joint"] for f in result["findings"] if f["kind"] == "gap"} == {
        "r_knee_study",
        "RHeel",
    }
    assert any(f["kind"] == "gap not filled" and f["joint"] == "LWrist" for f in result["findings"])

    # Undecided: the run's own choice (the swap left), its gaps filled as the run filled them.
    text, undecided = decided_trc(client, run_id)
    # ... as `mocapqa markers fill --apply confident` repairs and fills the same take.
    rule = repair_markers(raw, np.where(np.isnan(raw).any(-1), -1.0, 0.0), names, 60.0, "m")
    np.testing.assert_array_equal(undecided, rule.positions)
    np.testing.assert_array_equal(rule.filled, filled)
    assert np.isfinite(undecided[filled]).all()
    np.testing.assert_array_equal(undecided[~filled], raw[~filled])  # NaN where not filled

    # The header is the source's: rate, unit, names, frame numbers, times, first frame.
    source, decided = read_trc(corpus_dir / SOURCE), parse_trc(text, "decided.trc")
    assert (decided.fps, decided.length_unit, decided.names) == (60.0, "m", source.names)
    assert decided.frame_numbers is not None
    assert source.frame_numbers is not None
    np.testing.assert_array_equal(decided.frame_numbers, source.frame_numbers)
    np.testing.assert_array_equal(decided.times, source.times)
    assert decided.start_frame == source.start_frame == 0

    # Accepted: the two labels exchanged back over the swap only; every other sample as the
    # undecided take has it (the fills are chosen again, on the same gaps).
    a, b, start, end = SWAP
    pair, frames = [names.index(a), names.index(b)], slice(start, end + 1)
    response = client.post(
        f"/api/v1/runs/{run_id}/swaps/{swap['id']}/decisions", json={"decision": "accept"}
    )
    assert response.status_code == 201, response.text
    _, accepted = decided_trc(client, run_id)
    np.testing.assert_array_equal(accepted[frames, pair], clean[frames, pair])
    np.testing.assert_array_equal(accepted[frames, pair[::-1]], raw[frames, pair])
    exchanged = np.zeros(raw.shape[:2], dtype=bool)
    exchanged[frames, pair] = True
    assert not (exchanged & filled).any()
    np.testing.assert_array_equal(accepted[~exchanged & ~filled], raw[~exchanged & ~filled])
    assert np.isfinite(accepted[filled]).all()
    np.testing.assert_allclose(accepted[filled], undecided[filled], atol=5e-3)
    assert np.isnan(accepted[50:96, names.index("LWrist")]).all()

    # Rejected: as recorded again.
    response = client.post(
        f"/api/v1/runs/{run_id}/swaps/{swap['id']}/decisions", json={"decision": "reject"}
    )
    assert response.status_code == 201, response.text
    assert decided_trc(client, run_id)[0] == text


def test_the_decided_trc_answers_409_404_and_401_as_its_neighbours(
    client: TestClient,
    corpus_dir: Path,
    trc_run: dict[str, Any],
    cmu_walk: Path,
    upload: Uploader,
    wait_for_run: Waiter,
    tmp_path: Path,
) -> None:
    missing = "0" * 32
    assert client.get(f"/api/v1/runs/{missing}/decisions/trc").status_code == 404

    # A motion take: its decided download is BVH.
    motion = wait_for_run(client, upload(client, cmu_walk)["run_id"])
    answer = client.get(f"/api/v1/runs/{motion['id']}/decisions/trc")
    assert answer.status_code == 409
    assert "motion take" in answer.json()["detail"]
    assert "/decisions/bvh" in answer.json()["detail"]

    # A keypoint take (not markers): nothing to decide.
    csv = tmp_path / "balancing.csv"
    write_keypoints(csv, read_trc(corpus_dir / SOURCE))
    keypoints = wait_for_run(client, upload(client, csv)["run_id"])
    assert keypoints["status"] == "done", keypoints["error"]
    answer = client.get(f"/api/v1/runs/{keypoints['id']}/decisions/trc")
    assert answer.status_code == 409
    assert "keypoint take" in answer.json()["detail"]

    # A TRC take's run without the markers check.
    filtered = client.post(
        f"/api/v1/takes/{trc_run['take_id']}/runs", json={"checks": ["filter"]}
    ).json()
    assert wait_for_run(client, filtered["id"])["status"] == "done"
    answer = client.get(f"/api/v1/runs/{filtered['id']}/decisions/trc")
    assert answer.status_code == 409
    assert "markers check" in answer.json()["detail"]
    # ... and a TRC take has no decided C3D: the message names the TRC download.
    answer = client.get(f"/api/v1/runs/{trc_run['id']}/decisions/c3d")
    assert answer.status_code == 409
    assert "/decisions/trc" in answer.json()["detail"]

    # Signing a user in ends anonymous access; a viewer reads the download.
    accounts = client.app.state.accounts  # type: ignore[attr-defined]
    viewer = accounts.add_user("vi", Role.VIEWER)
    token = accounts.issue(viewer.id, "api", timedelta(days=1)).token
    assert client.get(f"/api/v1/runs/{trc_run['id']}/decisions/trc").status_code == 401
    decided_trc(client, trc_run["id"], Authorization=f"Bearer {token}")


def test_an_accepted_foot_lock_pins_a_trc_takes_foot_points_only(
    client: TestClient, trc_run: dict[str, Any]
) -> None:
    """As the decided C3D does (tests/api/test_swap_decisions.py): the foot points of the
    accepted lock's foot move, horizontally, around its contact; nothing else; rejected, the
    download is as it was."""
    run_id = trc_run["id"]
    locks = client.get(f"/api/v1/runs/{run_id}/decisions").json()["locks"]
    assert locks
    before_text, before = decided_trc(client, run_id)
    lock = locks[0]
    response = client.post(
        f"/api/v1/runs/{run_id}/feet/{lock['id']}/decisions", json={"decision": "accept"}
    )
    assert response.status_code == 201, response.text
    text, after = decided_trc(client, run_id)
    names = parse_trc(text, "decided.trc").names
    change = np.nan_to_num(np.abs(after - before))
    moved = [names[m] for m in np.flatnonzero(change.max(axis=(0, 2)) > 0)]
    # The left foot's keypoints (the feet check's foot points of this take), no other marker.
    assert lock["foot"] == "left"
    assert set(moved) == {"LAnkle", "LHeel", "LBigToe", "LSmallToe"}
    assert (change.max(axis=(0, 1)) > 0).sum() == 2  # the up axis keeps every value
    frames = np.flatnonzero(change.max(axis=(1, 2)) > 0)
    assert lock["start_frame"] - 10 <= frames.min() <= frames.max() <= lock["end_frame"] + 10
    response = client.post(
        f"/api/v1/runs/{run_id}/feet/{lock['id']}/decisions", json={"decision": "reject"}
    )
    assert response.status_code == 201, response.text
    assert decided_trc(client, run_id)[0] == before_text


def test_every_foot_lock_the_run_lists_can_be_downloaded(
    client: TestClient, trc_run: dict[str, Any]
) -> None:
    """The download checks the take with the thresholds the run's feet step used (a TRC take's
    are the keypoint defaults, not the C3D marker ones): every lock the run lists is found
    again, so accepting all of them gives a take, not a 409."""
    run_id = trc_run["id"]
    locks = client.get(f"/api/v1/runs/{run_id}/decisions").json()["locks"]
    assert len(locks) >= 2, locks
    for lock in locks:
        response = client.post(
            f"/api/v1/runs/{run_id}/feet/{lock['id']}/decisions", json={"decision": "accept"}
        )
        assert response.status_code == 201, response.text
    response = client.get(f"/api/v1/runs/{run_id}/decisions/trc")
    assert response.status_code == 200, response.text
    assert response.text.startswith("PathFileType")


FOOT_POINTS = ("Ankle", "Heel", "BigToe", "SmallToe")
"""The foot keypoints of the Pose2Sim take the feet check uses, after the side's letter."""


def test_a_feet_only_run_of_a_trc_take_gives_the_raw_take_with_its_accepted_locks(
    client: TestClient, swapped: Path, trc_run: dict[str, Any], wait_for_run: Waiter
) -> None:
    """A TRC take's run with the feet check and no markers check: its reviewers decide foot
    locks, and its decided TRC is the raw take (the swap left, the gaps NaN) with the accepted
    locks pinned, only the foot points of the lock's foot moving."""
    response = client.post(f"/api/v1/takes/{trc_run['take_id']}/runs", json={"checks": ["feet"]})
    assert response.status_code in (200, 201, 202), response.text
    run = wait_for_run(client, response.json()["id"])
    assert run["status"] == "done", run["error"]
    body = client.get(f"/api/v1/runs/{run['id']}/decisions").json()
    assert (body["item"], body["swaps"]) == ("swap", [])
    locks = body["locks"]
    assert locks

    # No lock accepted: the take's markers as read, every sample (NaN where missing).
    raw = read_trc(swapped)
    text, undecided = decided_trc(client, run["id"])
    assert parse_trc(text, "decided.trc").names == raw.names
    assert np.isnan(raw.positions).any()
    np.testing.assert_array_equal(undecided, raw.positions)

    lock = locks[0]
    response = client.post(
        f"/api/v1/runs/{run['id']}/feet/{lock['id']}/decisions", json={"decision": "accept"}
    )
    assert response.status_code == 201, response.text
    _, after = decided_trc(client, run["id"])
    change = np.nan_to_num(np.abs(after - undecided))
    moved = {raw.names[m] for m in np.flatnonzero(change.max(axis=(0, 2)) > 0)}
    side = lock["foot"][0].upper()
    assert moved == {f"{side}{point}" for point in FOOT_POINTS}
    assert (change.max(axis=(0, 1)) > 0).sum() == 2  # horizontally: the up axis keeps its values
    frames = np.flatnonzero(change.max(axis=(1, 2)) > 0)
    assert lock["start_frame"] - 10 <= frames.min() <= frames.max() <= lock["end_frame"] + 10
    # The C3D download is a C3D take's only.
    answer = client.get(f"/api/v1/runs/{run['id']}/decisions/c3d")
    assert answer.status_code == 409
    assert "/decisions/trc" in answer.json()["detail"]
