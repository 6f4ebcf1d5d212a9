"""Accept / reject per twist interval: history, the decided take, errors."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.io.bvh import parse_bvh, read_bvh
from mocapqa.io.bvh_write import channel_values, format_bvh
from mocapqa.store.decisions import IntervalDecisions
from mocapqa.twist.analysis import refined_hint
from mocapqa.twist.angles import chain_geometry
from mocapqa.twist.refine import refine_quats

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]


@pytest.fixture
def knees(corpus_dir: Path) -> Path:
    """The take with real knee twist errors."""
    return corpus_dir / "bvh" / "cmu" / "iclone" / "005_05.bvh"


@pytest.fixture
def knees_run(
    client: TestClient, knees: Path, upload: Uploader, wait_for_run: Waiter
) -> dict[str, Any]:
    """005_05 uploaded and analysed with the default options."""
    created = upload(client, knees)
    run = wait_for_run(client, created["run_id"])
    assert run["status"] == "done", run["error"]
    return run


def decide(client: TestClient, run_id: str, interval: int, decision: str, note: str = "") -> Any:
    response = client.post(
        f"/api/v1/runs/{run_id}/intervals/{interval}/decisions",
        json={"decision": decision, "note": note, "reviewer": "ana"},
    )
    assert response.status_code == 201, response.text
    return response.json()


def expected_bvh(knees: Path, intervals: list[dict[str, Any]], ids: set[int]) -> bytes:
    """The raw take with the levels of ``ids`` removed, built here from the levels alone."""
    raw = read_bvh(knees)
    geometries = [chain_geometry(raw.skeleton, c) for c in limb_chains(find_roles(raw.skeleton))]
    column = {raw.skeleton.names[g.chain.parent]: c for c, g in enumerate(geometries)}
    offsets = np.zeros((raw.n_frames, len(geometries)))
    for interval in intervals:
        if interval["id"] in ids:
            for start, end, value in interval["levels"]:
                offsets[start : end + 1, column[interval["joint"]]] = np.deg2rad(value)
    quats = refine_quats(raw.quats, geometries, offsets)
    changed = np.any(quats != raw.quats, axis=-1)
    motion = replace(raw, quats=quats, euler_hint_deg=refined_hint(raw, quats, changed))
    return format_bvh(motion).encode()


def test_decisions_are_history_and_the_download_has_exactly_the_accepted_levels(
    client: TestClient, knees: Path, knees_run: dict[str, Any]
) -> None:
    run_id = knees_run["id"]
    listed = client.get(f"/api/v1/runs/{run_id}/decisions")
    assert listed.status_code == 200, listed.text
    body = listed.json()
    intervals = body["intervals"]
    assert body["apply"] == "confident"
    assert body["history"] == []
    assert len(intervals) >= 2
    assert all(i["decision"] is None and i["corrected"] == i["applied"] for i in intervals)
    assert all(i["levels"] for i in intervals)

    # Accept one the run left alone (or the first), reject another; change a mind once.
    accepted = next((i["id"] for i in intervals if not i["applied"]), intervals[0]["id"])
    rejected = next(i["id"] for i in intervals if i["id"] != accepted)
    decide(client, run_id, accepted, "reject", "first look")
    decide(client, run_id, rejected, "reject")
    last = decide(client, run_id, accepted, "accept", "jump is real")
    assert last["client"] == "testclient"
    assert last["reviewer"] == "anonymous"  # who is signed in (none here), not the body's name

    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    history = body["history"]
    assert [(h["interval_id"], h["decision"]) for h in history] == [
        (accepted, "accept"),
        (rejected, "reject"),
        (accepted, "reject"),
    ]
    assert history[0]["note"] == "jump is real"
    assert history[0]["created_at"]
    by_id = {i["id"]: i for i in body["intervals"]}
    assert by_id[accepted]["decision"] == "accept"
    assert by_id[accepted]["corrected"]
    assert by_id[rejected]["decision"] == "reject"
    assert not by_id[rejected]["corrected"]
    undecided = {i["id"] for i in intervals if i["applied"]} - {accepted, rejected}
    ids = {accepted} | undecided
    assert {i for i, v in by_id.items() if v["corrected"]} == ids

    response = client.get(f"/api/v1/runs/{run_id}/decisions/bvh")
    assert response.status_code == 200, response.text
    assert "attachment" in response.headers["content-disposition"]
    assert response.content == expected_bvh(knees, intervals, ids)  # bit for bit
    # And it differs from the raw take exactly on the accepted interval's frames.
    raw, decided = read_bvh(knees), parse_bvh(response.content.decode(), "decided.bvh")
    moved = np.abs(channel_values(decided) - channel_values(raw)).max(axis=1) > 1e-3
    first = by_id[accepted]
    assert moved[first["start_frame"] : first["end_frame"] + 1].any()


def test_rejecting_every_interval_gives_the_raw_rotations_back(
    client: TestClient, knees: Path, knees_run: dict[str, Any]
) -> None:
    run_id = knees_run["id"]
    intervals = client.get(f"/api/v1/runs/{run_id}/decisions").json()["intervals"]
    assert any(i["applied"] for i in intervals)
    for interval in intervals:
        decide(client, run_id, interval["id"], "reject")
    content = client.get(f"/api/v1/runs/{run_id}/decisions/bvh").content
    raw, decided = read_bvh(knees), parse_bvh(content.decode(), "decided.bvh")
    np.testing.assert_allclose(decided.quats, raw.quats, atol=1e-6)
    np.testing.assert_allclose(channel_values(decided), channel_values(raw), atol=1e-6)
    # The run's own corrected take differs (it applied some), so this is not the default.
    corrected = client.get(f"/api/v1/runs/{run_id}/download/bvh").content
    assert corrected != content


def test_decision_errors_name_the_problem(
    client: TestClient,
    corpus_dir: Path,
    knees_run: dict[str, Any],
    upload: Uploader,
    wait_for_run: Waiter,
) -> None:
    run_id = knees_run["id"]
    n = len(client.get(f"/api/v1/runs/{run_id}/decisions").json()["intervals"])
    url = f"/api/v1/runs/{run_id}/intervals"
    assert client.post(f"{url}/{n}/decisions", json={"decision": "accept"}).status_code == 404
    bad = client.post(f"{url}/0/decisions", json={"decision": "maybe"})
    assert bad.status_code == 422
    assert bad.json()["field"].endswith("decision")
    missing = "0" * 32
    assert client.get(f"/api/v1/runs/{missing}/decisions").status_code == 404
    assert client.get(f"/api/v1/runs/{missing}/decisions/bvh").status_code == 404
    no_run = client.post(
        f"/api/v1/runs/{missing}/intervals/0/decisions", json={"decision": "accept"}
    )
    assert no_run.status_code == 404

    trc = corpus_dir / "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d"
    created = upload(client, trc / "S00_P00_T01_BalancingTrial_0-100.trc")
    assert wait_for_run(client, created["run_id"])["status"] == "done"
    # A marker take's decisions are on its swaps (tests/api/test_swap_decisions.py).
    listed = client.get(f"/api/v1/runs/{created['run_id']}/decisions")
    assert listed.status_code == 200, listed.text
    assert listed.json()["item"] == "swap"
    assert listed.json()["intervals"] == []
    for answer in (
        client.get(f"/api/v1/runs/{created['run_id']}/decisions/bvh"),
        client.post(
            f"/api/v1/runs/{created['run_id']}/intervals/0/decisions", json={"decision": "accept"}
        ),
    ):
        assert answer.status_code == 409
        assert "keypoint take" in answer.json()["detail"]

    limits_only = client.post(
        f"/api/v1/takes/{knees_run['take_id']}/runs", json={"checks": ["limits"]}
    ).json()
    assert wait_for_run(client, limits_only["id"])["status"] == "done"
    answer = client.get(f"/api/v1/runs/{limits_only['id']}/decisions")
    assert answer.status_code == 409
    assert "twist" in answer.json()["detail"]


def test_deleting_the_take_removes_its_decisions(
    client: TestClient, knees_run: dict[str, Any]
) -> None:
    run_id = knees_run["id"]
    decide(client, run_id, 0, "accept")
    store = IntervalDecisions(client.app.state.services.repository.engine)  # type: ignore[attr-defined]
    assert len(store.history(run_id)) == 1
    assert client.delete(f"/api/v1/takes/{knees_run['take_id']}").status_code == 204
    assert store.history(run_id) == []


def test_a_decision_records_the_client_address_of_a_signed_in_reviewer(
    client: TestClient, knees_run: dict[str, Any]
) -> None:
    """The history's ``client`` read ``user:3`` (the run-quota key) for a signed-in reviewer;
    docs/api.md says it is the client's address, as the audit log records it."""
    from datetime import timedelta

    from mocapqa.store.roles import Role

    accounts = client.app.state.accounts  # type: ignore[attr-defined]
    user = accounts.add_user("ana", Role.REVIEWER)
    token = accounts.issue(user.id, "api", timedelta(days=1)).token
    response = client.post(
        f"/api/v1/runs/{knees_run['id']}/intervals/0/decisions",
        json={"decision": "accept"},
        headers={"Authorization": f"Bearer {token}"},
    )
    assert response.status_code == 201, response.text
    assert response.json()["client"] == "testclient"
    assert response.json()["reviewer"] == "ana"
    history = client.get(
        f"/api/v1/runs/{knees_run['id']}/decisions", headers={"Authorization": f"Bearer {token}"}
    ).json()["history"]
    assert [h["client"] for h in history] == ["testclient"]


def test_accepted_foot_locks_apply_on_top_of_the_accepted_intervals(
    client: TestClient, knees: Path, knees_run: dict[str, Any]
) -> None:
    """The decided BVH removes the decided intervals' levels, then locks the accepted feet
    (tests/api/test_feet_decisions.py): against the same intervals without the lock, only the
    legs move."""
    from tests.api.test_feet_decisions import decide_lock, leg_joints

    from mocapqa.kinematics.forward import forward_kinematics

    run_id = knees_run["id"]
    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    intervals, locks = body["intervals"], body["locks"]
    assert locks
    first = intervals[0]["id"]
    decide(client, run_id, first, "accept")
    ids = {first} | {i["id"] for i in intervals if i["applied"]}
    without_lock = client.get(f"/api/v1/runs/{run_id}/decisions/bvh").content
    assert without_lock == expected_bvh(knees, intervals, ids)

    lock = locks[-1]
    decide_lock(client, run_id, lock["id"], "accept")
    with_lock = client.get(f"/api/v1/runs/{run_id}/decisions/bvh").content
    assert with_lock != without_lock
    old = parse_bvh(without_lock.decode(), "intervals.bvh")
    new = parse_bvh(with_lock.decode(), "locked.bvh")
    upper = [j for j in range(new.skeleton.n_joints) if j not in leg_joints(knees)]
    np.testing.assert_array_equal(
        forward_kinematics(new)[1][:, upper], forward_kinematics(old)[1][:, upper]
    )
    assert body["history"] == []
    history = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    assert [h["interval_id"] for h in history["history"]] == [first]
    assert [h["lock_id"] for h in history["lock_history"]] == [lock["id"]]
