"""Accept / reject per foot lock (the lock of a skate finding): history, the decided take with
exactly the accepted locks on the legs, errors, and the stored rows' kinds.

The take is a real walk (Bandai, centimetres) with a 5 cm slide injected through the leg into
one contact (:func:`mocapqa.feet.inject.leg_slide_offsets`, as ``tests/feet/test_feet_fix.py``
does), so the run has a skate finding there whatever else its feet check flags."""

from __future__ import annotations

from datetime import timedelta
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from sqlalchemy import text
from tests.api.conftest import Uploader, Waiter
from tests.api.test_decisions import expected_bvh
from tests.store.conftest import database_params, database_url

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles
from mocapqa.feet.fix import foot_rig, shift_ankles
from mocapqa.feet.inject import leg_slide_offsets
from mocapqa.feet.points import SIDES
from mocapqa.feet.tracks import horizontal_axes
from mocapqa.io.bvh import parse_bvh, read_bvh
from mocapqa.io.bvh_write import channel_values, write_bvh
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.pipeline.feet import check_take_feet
from mocapqa.store.decisions import IntervalDecisions
from mocapqa.store.repository import Repository
from mocapqa.store.roles import Role
from mocapqa.store.upgrade import downgrade_database, upgrade_database

WALK = Path("bvh/bandai/dataset-1_walk_normal_001.bvh")
"""A real walk in centimetres at 30 fps."""
SLIDE_CM = 5.0
BLEND_FRAMES = 3
"""The lock's blend at 30 fps (``BLEND_S`` 0.1 s)."""


def write_slid_walk(corpus_dir: Path, folder: Path) -> tuple[Path, str, int, int]:
    """The walk with a 5 cm slide injected through the leg into its sixth contact, written as
    BVH: its path, and the contact's foot, first and last frame."""
    raw = read_bvh(corpus_dir / WALK)
    _, report, skipped = check_take_feet(raw)
    contact = report.contacts[5]
    displacement = np.zeros(3)
    displacement[list(horizontal_axes(report.up.axis))] = [SLIDE_CM * 0.6, SLIDE_CM * 0.8]
    start, end = contact.start + skipped, contact.end + skipped
    offsets, changed = leg_slide_offsets(
        raw.n_frames, SIDES.index(contact.foot), start, end, end, displacement, BLEND_FRAMES
    )
    motion, _ = shift_ankles(raw, foot_rig(raw), offsets, changed)
    path = folder / "walk_slid.bvh"
    write_bvh(path, motion)
    return path, contact.foot, start, end


def injected_skate(result: dict[str, Any], foot: str, start: int, end: int) -> dict[str, Any]:
    """The run's skate finding on the injected contact."""
    return next(
        f
        for f in result["findings"]
        if f["kind"] == "skate" and f["foot"] == foot and f["start_frame"] <= end
        and f["end_frame"] >= start
    )  # fmt: skip


@pytest.fixture
def slid(corpus_dir: Path, tmp_path: Path) -> tuple[Path, str, int, int]:
    return write_slid_walk(corpus_dir, tmp_path)


@pytest.fixture
def skate_run(
    client: TestClient, slid: tuple[Path, str, int, int], upload: Uploader, wait_for_run: Waiter
) -> dict[str, Any]:
    created = upload(client, slid[0])
    run = wait_for_run(client, created["run_id"])
    assert run["status"] == "done", run["error"]
    result = client.get(f"/api/v1/runs/{run['id']}/result").json()
    return {**run, "skate": injected_skate(result, *slid[1:]), "result": result}


def decide_lock(
    client: TestClient, run_id: str, lock_id: str, decision: str, note: str = ""
) -> Any:
    response = client.post(
        f"/api/v1/runs/{run_id}/feet/{lock_id}/decisions",
        json={"decision": decision, "note": note},
    )
    assert response.status_code == 201, response.text
    return response.json()


def leg_joints(path: Path) -> set[int]:
    """The joints of both legs' subtrees (upper leg down), the only ones a lock may move."""
    skeleton = read_bvh(path).skeleton
    rig = find_roles(skeleton)
    legs = {rig.joint(side, "upper_leg") for side in ("left", "right")}
    inside: set[int] = set()
    for joint in range(skeleton.n_joints):
        walk: int = joint
        while walk >= 0:
            if walk in legs:
                inside.add(joint)
                break
            walk = int(skeleton.parents[walk])
    return inside


def contact_of(result: dict[str, Any], skate: dict[str, Any]) -> dict[str, Any]:
    """The contact of the run's ``series.feet`` that the skate lies in."""
    return next(
        c
        for c in result["series"]["feet"]["contacts"]
        if c["foot"] == skate["foot"] and c["start"] <= skate["end_frame"]
        and c["end"] >= skate["start_frame"]
    )  # fmt: skip


def test_an_accepted_lock_moves_only_the_legs_and_undecided_locks_are_not_applied(
    client: TestClient, slid: tuple[Path, str, int, int], skate_run: dict[str, Any]
) -> None:
    take_path = slid[0]
    run_id = skate_run["id"]
    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    locks = body["locks"]
    skates = [f for f in skate_run["result"]["findings"] if f["kind"] == "skate"]
    assert [lock["id"] for lock in locks] == [f["id"] for f in skates]
    lock = next(lock for lock in locks if lock["id"] == skate_run["skate"]["id"])
    assert all(lock["decision"] is None and not lock["applied"] for lock in locks)
    assert body["lock_history"] == []
    intervals = body["intervals"]
    applied = {i["id"] for i in intervals if i["applied"]}

    # Cleanup is off by default: undecided, the download is the interval-decided take, bit for
    # bit as it was written before locks could be decided.
    before = client.get(f"/api/v1/runs/{run_id}/decisions/bvh")
    assert before.status_code == 200, before.text
    assert before.content == expected_bvh(take_path, intervals, applied)

    decide_lock(client, run_id, lock["id"], "accept", "slides")
    locked = client.get(f"/api/v1/runs/{run_id}/decisions/bvh").content
    assert locked != before.content
    raw_decided = parse_bvh(before.content.decode(), "before.bvh")
    decided = parse_bvh(locked.decode(), "locked.bvh")
    legs = leg_joints(take_path)
    upper = [j for j in range(decided.skeleton.n_joints) if j not in legs]
    # Upper body untouched, through forward kinematics: every joint outside the legs keeps its
    # world position and orientation on every frame, and the root its translation.
    quats_before, positions_before = forward_kinematics(raw_decided)
    quats_after, positions_after = forward_kinematics(decided)
    np.testing.assert_array_equal(positions_after[:, upper], positions_before[:, upper])
    np.testing.assert_array_equal(quats_after[:, upper], quats_before[:, upper])
    np.testing.assert_array_equal(decided.translations, raw_decided.translations)
    # The foot does change, on the lock's contact and its blends only, and slides less.
    ankle = find_roles(decided.skeleton).joint(lock["foot"], "foot")
    assert ankle is not None
    moved = np.abs(positions_after[:, ankle] - positions_before[:, ankle]).max(axis=1) > 1e-4
    contact = contact_of(skate_run["result"], skate_run["skate"])
    assert moved[contact["start"] : contact["end"] + 1].any()
    frames = np.flatnonzero(moved)
    assert frames.min() >= contact["start"] - BLEND_FRAMES
    assert frames.max() <= contact["end"] + BLEND_FRAMES
    changed = np.abs(channel_values(decided) - channel_values(raw_decided)).max(axis=0)
    assert changed.max() > 1e-3
    after = [
        f.size for f in check_take_feet(decided)[1].findings
        if f.kind == "skate" and f.foot == lock["foot"] and f.start <= contact["end"]
        and f.end >= contact["start"]
    ]  # fmt: skip
    before_sizes = [
        f.size for f in check_take_feet(raw_decided)[1].findings
        if f.kind == "skate" and f.foot == lock["foot"] and f.start <= contact["end"]
        and f.end >= contact["start"]
    ]  # fmt: skip
    assert before_sizes
    assert max(after, default=0.0) < 0.5 * max(before_sizes)

    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    by_id = {lock["id"]: lock for lock in body["locks"]}
    assert by_id[lock["id"]]["decision"] == "accept"
    assert by_id[lock["id"]]["applied"]
    assert sum(lock["applied"] for lock in body["locks"]) == 1
    assert [(h["lock_id"], h["decision"], h["item"]) for h in body["lock_history"]] == [
        (lock["id"], "accept", "lock")
    ]
    assert body["lock_history"][0]["note"] == "slides"
    assert body["history"] == []  # the twist intervals' history holds none of them
    assert all(i["decision"] is None for i in body["intervals"])

    # Undo: the other choice; the newest counts and the download is the one before again.
    decide_lock(client, run_id, lock["id"], "reject")
    assert client.get(f"/api/v1/runs/{run_id}/decisions/bvh").content == before.content
    body = client.get(f"/api/v1/runs/{run_id}/decisions").json()
    assert [h["decision"] for h in body["lock_history"]] == ["reject", "accept"]
    assert not any(lock["applied"] for lock in body["locks"])


def test_lock_decision_errors(
    client: TestClient, skate_run: dict[str, Any], wait_for_run: Waiter
) -> None:
    run_id = skate_run["id"]
    lock_id = skate_run["skate"]["id"]
    url = f"/api/v1/runs/{run_id}/feet"
    unknown = client.post(f"{url}/skate-left-100000/decisions", json={"decision": "accept"})
    assert unknown.status_code == 404
    assert "skate-" in unknown.json()["detail"]
    assert client.post(f"{url}/{lock_id}/decisions", json={"decision": "maybe"}).status_code == 422
    missing = "0" * 32
    gone = client.post(
        f"/api/v1/runs/{missing}/feet/{lock_id}/decisions", json={"decision": "accept"}
    )
    assert gone.status_code == 404

    # A run without the feet check has no locks to decide.
    twist_only = client.post(
        f"/api/v1/takes/{skate_run['take_id']}/runs", json={"checks": ["twist"]}
    ).json()
    assert wait_for_run(client, twist_only["id"])["status"] == "done"
    answer = client.post(
        f"/api/v1/runs/{twist_only['id']}/feet/{lock_id}/decisions", json={"decision": "accept"}
    )
    assert answer.status_code == 409
    assert "feet" in answer.json()["detail"]
    assert client.get(f"/api/v1/runs/{twist_only['id']}/decisions").json()["locks"] == []

    # A run with the feet check only: its locks are decided, and its decided BVH is the raw
    # take with the accepted locks.
    feet_only = client.post(
        f"/api/v1/takes/{skate_run['take_id']}/runs", json={"checks": ["feet"]}
    ).json()
    assert wait_for_run(client, feet_only["id"])["status"] == "done"
    listed = client.get(f"/api/v1/runs/{feet_only['id']}/decisions")
    assert listed.status_code == 200, listed.text
    assert listed.json()["intervals"] == []
    assert lock_id in [lock["id"] for lock in listed.json()["locks"]]
    plain = client.get(f"/api/v1/runs/{feet_only['id']}/decisions/bvh")
    assert plain.status_code == 200, plain.text
    decide_lock(client, feet_only["id"], lock_id, "accept")
    locked = client.get(f"/api/v1/runs/{feet_only['id']}/decisions/bvh")
    assert locked.status_code == 200, locked.text
    assert locked.content != plain.content

    # Deciding takes the review role (signing a user in ends anonymous access).
    accounts = client.app.state.accounts  # type: ignore[attr-defined]
    viewer = accounts.add_user("vi", Role.VIEWER)
    token = accounts.issue(viewer.id, "api", timedelta(days=1)).token
    refused = client.post(
        f"{url}/{lock_id}/decisions",
        json={"decision": "accept"},
        headers={"Authorization": f"Bearer {token}"},
    )
    assert refused.status_code == 403


def test_a_run_that_locks_feet_writes_them_and_undecided_locks_follow_the_run(
    client: TestClient,
    slid: tuple[Path, str, int, int],
    skate_run: dict[str, Any],
    wait_for_run: Waiter,
) -> None:
    take_path, take_id = slid[0], skate_run["take_id"]
    lock_id = skate_run["skate"]["id"]
    runs = f"/api/v1/takes/{take_id}/runs"
    # The option is checked before a run is queued: contact ids and junk are refused.
    wide_digits = "skate-left-\uff11\uff12"
    for bad in ("contact-left-3", "skate-up-3", "all", "", "skate-left-3,", wide_digits):
        answer = client.post(runs, json={"checks": ["feet"], "feet_apply": bad})
        assert answer.status_code == 422, (bad, answer.text)
        assert "feet_apply" in answer.text
    # An id the take does not have fails the run, naming it.
    unknown = client.post(runs, json={"checks": ["feet"], "feet_apply": "skate-left-99999"})
    failed = wait_for_run(client, unknown.json()["id"])
    assert failed["status"] == "failed"
    assert "skate-left-99999" in failed["error"]

    created = client.post(runs, json={"checks": ["feet"], "feet_apply": "skates"}).json()
    run = wait_for_run(client, created["id"])
    assert run["status"] == "done", run["error"]
    assert run["options"]["feet_apply"] == "skates"
    result = client.get(f"/api/v1/runs/{run['id']}/result").json()
    skates = [f for f in result["findings"] if f["kind"] == "skate"]
    assert lock_id in [f["id"] for f in skates]
    assert all(f["applied"] is True and "locked" in f["readout"] for f in skates)
    assert all(f["applied"] is None for f in result["findings"] if f["kind"] != "skate")

    # The run's corrected take has every skate's contact locked, the legs only.
    corrected = parse_bvh(client.get(f"/api/v1/runs/{run['id']}/download/bvh").content, "c.bvh")
    raw = read_bvh(take_path)
    legs = leg_joints(take_path)
    upper = [j for j in range(raw.skeleton.n_joints) if j not in legs]
    positions_raw = forward_kinematics(raw)[1]
    positions_fixed = forward_kinematics(corrected)[1]
    np.testing.assert_allclose(positions_fixed[:, upper], positions_raw[:, upper], atol=1e-4)
    contact = contact_of(skate_run["result"], skate_run["skate"])

    def slide(motion: Motion) -> float:
        """The largest skate the feet check finds on the injected contact, take units."""
        return max(
            (f.size for f in check_take_feet(motion)[1].findings
             if f.kind == "skate" and f.foot == contact["foot"] and f.start <= contact["end"]
             and f.end >= contact["start"]),
            default=0.0,
        )  # fmt: skip

    assert slide(corrected) < 0.5 * slide(raw)

    # Undecided, every lock follows the run, so the reviewed take locks what the run locked.
    body = client.get(f"/api/v1/runs/{run['id']}/decisions").json()
    assert body["lock_apply"] == "skates"
    assert body["locks"]
    assert all(lock["run_applied"] and lock["applied"] for lock in body["locks"])
    decided_url = f"/api/v1/runs/{run['id']}/decisions/bvh"
    following = parse_bvh(client.get(decided_url).content, "d.bvh")
    np.testing.assert_allclose(forward_kinematics(following)[1], positions_fixed, atol=1e-3)
    # A rejected lock is undone in the reviewed take; the others stay.
    decide_lock(client, run["id"], lock_id, "reject")
    body = client.get(f"/api/v1/runs/{run['id']}/decisions").json()
    kept = {lock["id"]: lock["applied"] for lock in body["locks"]}
    assert kept.pop(lock_id) is False
    assert all(kept.values())
    undone = parse_bvh(client.get(decided_url).content, "u.bvh")
    assert slide(undone) > 0.9 * slide(raw)


def take_values(name: str) -> dict[str, Any]:
    return {
        "name": name, "format": "bvh", "kind": "motion", "size_bytes": 10,
        "sha256": name.encode().hex().ljust(64, "0")[:64], "n_frames": 5, "fps": 30.0,
        "n_joints": 2, "file_name": name, "shoot_id": None,
    }  # fmt: skip


@pytest.mark.parametrize("kind", database_params())
def test_rows_made_before_locks_keep_their_meaning(kind: str, tmp_path: Path) -> None:
    """Revision 0011: rows written at 0010 are twist interval (or swap) decisions; a lock's
    rows are apart from them, and go when migrating back."""
    repository = Repository(database_url(kind, tmp_path))
    _, run_id = repository.add_take(take_values("a.bvh"), {})
    repository.finish_run(run_id, {"qa": {"rig": "cmu"}}, None, 0.1)
    downgrade_database(repository.engine, "0010")
    with repository.engine.begin() as conn:
        conn.execute(
            text(
                "INSERT INTO interval_decisions (run_id, interval_id, decision, note, reviewer,"
                " client, created_at) VALUES (:run, 3, 'accept', '', 'ana', 'x', :t)"
            ),
            {"run": run_id, "t": "2026-12-01T00:00:00+00:00"},
        )
    upgrade_database(repository.engine)
    decisions = IntervalDecisions(repository.engine)
    assert decisions.latest(run_id) == {3: "accept"}
    assert decisions.latest_locks(run_id) == {}
    [row] = decisions.history(run_id)
    assert (row["item_kind"], row["interval_id"], row["lock_id"]) == ("correction", 3, None)

    decisions.add_lock(run_id, "skate-left-3", "accept", "", "ana", "x")
    decisions.add_lock(run_id, "skate-left-3", "reject", "", "ana", "x")
    decisions.add(run_id, 3, "reject", "", "ana", "x")
    assert decisions.latest(run_id) == {3: "reject"}
    assert decisions.latest_locks(run_id) == {"skate-left-3": "reject"}
    assert [r["decision"] for r in decisions.history(run_id, "lock")] == ["reject", "accept"]
    assert [r["interval_id"] for r in decisions.history(run_id)] == [3, 3]

    downgrade_database(repository.engine, "0010")
    with repository.engine.connect() as conn:
        kept = conn.execute(text("SELECT interval_id FROM interval_decisions")).scalars().all()
    assert kept == [3, 3]
    upgrade_database(repository.engine)
    assert decisions.latest(run_id) == {3: "reject"}
    repository.close()


@pytest.mark.parametrize("kind", database_params())
def test_lock_decisions_are_not_shoot_labels(kind: str, tmp_path: Path) -> None:
    from mocapqa.store.shoots import ShootStore

    repository = Repository(database_url(kind, tmp_path))
    shoot = ShootStore(repository.engine).create("day")["id"]
    _, first_run = repository.add_take({**take_values("a.bvh"), "shoot_id": shoot}, {})
    repository.finish_run(first_run, {"qa": {"rig": "cmu"}}, None, 0.1)
    decisions = IntervalDecisions(repository.engine)
    decisions.add(first_run, 1, "accept", "", "ana", "x")
    # A lock decided later on a newer run of the take does not make that run the decided one.
    take_id = repository.get_run(first_run)["take_id"]
    rerun = repository.add_run(take_id, {})
    repository.finish_run(rerun, {"qa": {"rig": "cmu"}}, None, 0.1)
    decisions.add_lock(rerun, "skate-right-7", "accept", "", "ana", "x")
    decisions.add_lock(first_run, "skate-left-2", "reject", "", "ana", "x")
    labels = decisions.shoot_labels(shoot)
    assert [(r["run_id"], r["interval_id"], r["decision"]) for r in labels] == [
        (first_run, 1, "accept")
    ]
    repository.close()
