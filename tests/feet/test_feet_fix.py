"""Foot locking on a real BVH walk: a slide injected through the leg is removed, nothing but
the legs moves, frames away from the locked contacts stay bit for bit, and the ``feet fix``
command keeps its contract."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.feet.check import FeetReport, check_feet
from mocapqa.feet.contacts import Contact
from mocapqa.feet.findings import Finding
from mocapqa.feet.fix import FootRig, fix_feet, foot_rig, lock_feet, shift_ankles
from mocapqa.feet.fix_choice import (
    check_apply,
    choose_locks,
    finding_confidence,
    locked_findings,
)
from mocapqa.feet.ik import leg_subtree, solve_leg
from mocapqa.feet.inject import leg_slide_offsets
from mocapqa.feet.lock import BLEND_S, Lock
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES
from mocapqa.feet.tracks import horizontal_axes
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import format_bvh, write_bvh
from mocapqa.io.formats import read_take
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import rotate
from mocapqa.pipeline.feet import check_take_feet, motion_foot_points
from mocapqa_bench.feet_cleanup import cleanup_trials

TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
WALK = "bvh/bandai/dataset-1_walk_normal_001.bvh"  # centimetres, 30 fps
SLIDE_CM = 5.0


@dataclasses.dataclass(frozen=True)
class Slid:
    raw: Motion
    motion: Motion
    rig: FootRig
    report: FeetReport
    contact: Contact
    leg_length: float


@pytest.fixture(scope="module")
def slid(corpus_dir: Path) -> Slid:
    """The Bandai walk with a 5 cm slide injected through the leg into its sixth contact."""
    raw = read_bvh(corpus_dir / WALK, length_unit="cm")
    points, skipped = motion_foot_points(raw)
    assert skipped == 0
    clean = check_feet(points)
    contact = clean.contacts[5]
    rig = foot_rig(raw)
    displacement = np.zeros(3)
    displacement[list(horizontal_axes(clean.up.axis))] = [SLIDE_CM * 0.6, SLIDE_CM * 0.8]
    offsets, changed = leg_slide_offsets(
        raw.n_frames, SIDES.index(contact.foot), contact.start, contact.end, contact.end,
        displacement, 3,
    )  # fmt: skip
    motion, miss = shift_ankles(raw, rig, offsets, changed)
    assert miss.max() < 1e-6
    _, report, _ = check_take_feet(motion)
    return Slid(raw, motion, rig, report, contact, points.leg_length)


JOINTS = FeetParams(sole_pivot=False)
"""The skate check reading the joints, as the lock holds them (not the sole under them)."""


def _travel_cm(motion: Motion, foot: str, start: int, end: int) -> float:
    """The check's travel of the contact (skate with no threshold, read at the joints), cm."""
    points, _ = motion_foot_points(motion)
    report = check_feet(points, dataclasses.replace(JOINTS, skate_travel=0.0))
    return max(
        (f.size for f in report.findings
         if f.kind == "skate" and f.foot == foot and f.start <= end and f.end >= start),
        default=0.0,
    )  # fmt: skip


def _lock_all(slid: Slid) -> tuple[Motion, np.ndarray, list[Lock]]:
    locks = [Lock(c.foot, c.start, c.end) for c in slid.report.contacts]
    result = lock_feet(
        slid.motion, slid.rig, slid.report.up, locks, 0.1 * slid.leg_length, slid.leg_length
    )
    return result.motion, result.changed, locks


def test_the_injected_slide_is_found_and_the_lock_removes_it(slid: Slid) -> None:
    c = slid.contact
    skates = [f for f in slid.report.findings if f.kind == "skate" and f.foot == c.foot]
    assert any(f.start <= c.end and f.end >= c.start for f in skates)
    assert _travel_cm(slid.motion, c.foot, c.start, c.end) > 4.0
    fixed, _, _ = _lock_all(slid)
    assert _travel_cm(fixed, c.foot, c.start, c.end) <= 0.5
    _, after, _ = check_take_feet(fixed, params=JOINTS)
    assert not [f for f in after.findings if f.kind == "skate"]


def test_only_the_legs_move_and_frames_away_from_the_locks_stay_bit_for_bit(slid: Slid) -> None:
    fixed, changed, locks = _lock_all(slid)
    skeleton = slid.motion.skeleton
    legs = leg_subtree(skeleton, slid.rig.legs[0].hip) | leg_subtree(skeleton, slid.rig.legs[1].hip)
    _, before = forward_kinematics(slid.motion)
    _, after = forward_kinematics(fixed)
    assert np.array_equal(before[:, ~legs], after[:, ~legs])
    assert np.array_equal(slid.motion.translations, fixed.translations)
    # Only hip, knee and ankle rotations change.
    solved = [j for leg in slid.rig.legs for j in (leg.hip, leg.knee, leg.ankle)]
    others = np.setdiff1d(np.arange(skeleton.n_joints), solved)
    assert np.array_equal(slid.motion.quats[:, others], fixed.quats[:, others])
    # The changed frames are the locked contacts and their blends, nothing else.
    blend = round(BLEND_S * slid.motion.fps)
    window = np.zeros_like(changed)
    for lock in locks:
        window[max(lock.start - blend, 0) : lock.end + blend + 1, SIDES.index(lock.foot)] = True
    assert np.array_equal(changed, window)
    for foot, leg in enumerate(slid.rig.legs):
        still = ~window[:, foot]
        assert still.any()
        joints = leg_subtree(skeleton, leg.hip)
        assert np.array_equal(slid.motion.quats[still][:, joints], fixed.quats[still][:, joints])
        assert np.array_equal(before[still][:, joints], after[still][:, joints])


def _sole_travels_cm(motion: Motion) -> list[float]:
    """The check's travel of every contact (skate with no threshold, read at the sole), cm."""
    points, _ = motion_foot_points(motion)
    report = check_feet(points, dataclasses.replace(FeetParams(), skate_travel=0.0))
    return [f.size for f in report.findings if f.kind == "skate"]


def test_the_lock_holds_the_sole_the_check_reads(slid: Slid) -> None:
    points, report, skipped = check_take_feet(slid.motion)
    fixed = fix_feet(slid.motion, points, report, skipped, "all", FeetParams())
    assert isinstance(fixed.take, Motion)
    assert len(fixed.chosen) == len(report.contacts)
    # Read at the sole, every locked contact travels at most 0.5 cm; holding the joints
    # instead leaves the sole under a rolling foot moving (more than 0.5 cm somewhere).
    at_sole = _sole_travels_cm(fixed.take)
    assert at_sole
    assert max(at_sole) <= 0.5
    joints, _, _ = _lock_all(slid)
    assert max(_sole_travels_cm(joints)) > max(at_sole)
    _, after, _ = check_take_feet(fixed.take)
    assert not [f for f in after.findings if f.kind == "skate"]
    # Still only the legs: every joint outside the hips' subtrees keeps its world position.
    skeleton = slid.motion.skeleton
    legs = leg_subtree(skeleton, slid.rig.legs[0].hip) | leg_subtree(skeleton, slid.rig.legs[1].hip)
    _, before_world = forward_kinematics(slid.motion)
    _, after_world = forward_kinematics(fixed.take)
    assert np.array_equal(before_world[:, ~legs], after_world[:, ~legs])
    assert np.all(fixed.after <= fixed.before + 1e-9)


def test_the_ik_reaches_a_reachable_target_keeps_the_foot_and_clamps_the_rest(
    slid: Slid,
) -> None:
    motion, leg = slid.raw, slid.rig.legs[0]
    world_quats, world = forward_kinematics(motion)
    frames = np.arange(0, motion.n_frames, 7)
    shift = np.array([3.0, -1.0, 2.0])  # cm
    targets = world[frames, leg.ankle] + shift
    quats, miss = solve_leg(
        motion.skeleton, leg, motion.quats[frames], world_quats[frames], world[frames], targets
    )
    moved = Motion(motion.skeleton, quats, motion.translations[frames], motion.fps)
    new_quats, new_world = forward_kinematics(moved)
    reachable = miss == 0
    assert reachable.mean() > 0.5
    assert np.abs(new_world[reachable, leg.ankle] - targets[reachable]).max() < 1e-9
    # The foot keeps its world orientation: its bones point the same way.
    axis = np.array([0.0, 0.0, 1.0])
    assert np.allclose(
        rotate(new_quats[:, leg.ankle], axis), rotate(world_quats[frames, leg.ankle], axis),
        atol=1e-12,
    )  # fmt: skip
    # Far out of reach: the leg goes as far as it can toward the target, and says so.
    far = world[frames, leg.hip] + np.array([0.0, -500.0, 0.0])
    _, miss_far = solve_leg(
        motion.skeleton, leg, motion.quats[frames], world_quats[frames], world[frames], far
    )
    assert np.all(miss_far > 300.0)


def test_choosing_locks_by_confidence_ids_and_errors(slid: Slid) -> None:
    contacts, findings = slid.report.contacts, slid.report.findings

    def by_id_of(finding: Finding) -> list[Contact]:
        return choose_locks(f"skate-{finding.foot}-{finding.start}", contacts, findings)

    assert choose_locks("none", contacts, findings) == []
    assert len(choose_locks("all", contacts, findings)) == len(contacts)
    skate = next(f for f in findings if f.kind == "skate")
    confident = choose_locks("confident", contacts, findings)
    assert [(c.foot, c.start) for c in confident] == [(c.foot, c.start) for c in by_id_of(skate)]
    assert choose_locks("confident", contacts, findings, confident=1.01) == []
    by_id = by_id_of(skate)
    assert len(by_id) == 1
    assert by_id[0].foot == skate.foot
    first = contacts[0]
    assert choose_locks(f"contact-{first.foot}-{first.start}", contacts, findings) == [first]
    # `skates`: the contact of every skate finding, whatever its confidence; the skate findings
    # a choice locks are the run's `applied` ones.
    skates = [f for f in findings if f.kind == "skate"]
    every = {(c.foot, c.start) for f in skates for c in by_id_of(f)}
    assert {(c.foot, c.start) for c in choose_locks("skates", contacts, findings)} == every
    ids = {f"skate-{f.foot}-{f.start}" for f in skates}
    assert locked_findings("skates", contacts, findings) == ids
    assert locked_findings("none", contacts, findings) == set()
    confident_ids = locked_findings("confident", contacts, findings)
    assert confident_ids <= ids
    assert confident_ids == {
        f"skate-{f.foot}-{f.start}" for f in skates if (finding_confidence(f, contacts) or 0) >= 0.5
    }
    assert locked_findings(f"skate-{skate.foot}-{skate.start}", contacts, findings) >= {
        f"skate-{skate.foot}-{skate.start}"
    }


def test_a_run_option_names_a_choice_or_skate_ids_only() -> None:
    assert check_apply(" skates ") == "skates"
    assert check_apply("skate-left-120, skate-right-3") == "skate-left-120,skate-right-3"
    for bad in ("all", "contact-left-3", "skate-left-", "skate-up-3", "", ",", "x" * 5000):
        with pytest.raises(InputError, match="skate findings"):
            check_apply(bad)
    with pytest.raises(InputError):
        check_apply(",".join(["skate-left-1"] * 1001))


def test_feet_fix_writes_the_take_and_the_report(
    slid: Slid, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    take = tmp_path / "slid.bvh"
    write_bvh(take, slid.motion)
    assert main(["feet", "check", str(take), "--length-unit", "cm", "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    skate = next(f for f in check["findings"] if f["kind"] == "skate")
    assert skate["id"] == f"skate-{skate['foot']}-{skate['start']}"
    assert 0.0 < skate["confidence"] <= 1.0
    assert all(c["id"].startswith("contact-") for c in check["contacts"])

    out, report_path = tmp_path / "fixed.bvh", tmp_path / "report.json"
    args = ["feet", "fix", str(take), "-o", str(out), "--length-unit", "cm"]
    assert main([*args, "--apply", skate["id"], "--report", str(report_path)]) == 0
    assert skate["id"] in capsys.readouterr().out  # the table
    report = json.loads(report_path.read_text(encoding="utf-8"))
    item = next(f for f in report["findings"] if f["id"] == skate["id"])
    assert item["applied"] is True
    assert item["slide_before_cm"] > 4.0
    assert item["slide_after_cm"] <= 0.5
    assert item["skate_after"] is None
    assert report["summary"]["contacts_locked"] == 1
    assert sum(c["applied"] for c in report["contacts"]) == 1
    assert read_bvh(out).n_frames == slid.motion.n_frames

    # --apply none writes the same motion as the input.
    assert main([*args, "--apply", "none", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not any(f["applied"] for f in report["findings"])
    assert out.read_text(encoding="utf-8") == format_bvh(read_bvh(take))


@pytest.mark.parametrize("apply", ["bogus", "", "penetration-left-3", "contact-left-99999"])
def test_a_bad_apply_exits_with_the_input_error_code(
    cmu_walk: Path, tmp_path: Path, apply: str, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out.bvh"
    assert main(["feet", "fix", str(cmu_walk), "-o", str(out), "--apply", apply]) == 3
    assert "Expected --apply" in capsys.readouterr().err
    assert not out.exists()


def test_keypoint_feet_are_pinned_and_nothing_else_moves(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    trc = corpus_dir / TRC
    none, pinned = tmp_path / "none.trc", tmp_path / "all.trc"
    assert main(["feet", "fix", str(trc), "-o", str(none), "--apply", "none"]) == 0
    capsys.readouterr()
    assert main(["feet", "fix", str(trc), "-o", str(pinned), "--apply", "all", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    raw, moved = read_take(none), read_take(pinned)
    assert isinstance(raw, KeypointSequence)
    assert isinstance(moved, KeypointSequence)
    feet = [i for i, n in enumerate(raw.names) if any(t in n for t in ("Ankle", "Heel", "Toe"))]
    others = np.setdiff1d(np.arange(len(raw.names)), feet)
    assert np.array_equal(raw.positions[:, others], moved.positions[:, others], equal_nan=True)
    changed = ~np.all(raw.positions == moved.positions, axis=(1, 2))
    assert changed.any()
    skate = next(f for f in report["findings"] if f["kind"] == "skate")
    assert skate["applied"] is True
    assert skate["slide_after_cm"] < skate["slide_before_cm"]


def test_the_cleanup_bench_on_the_cmu_walk(cmu_walk: Path) -> None:
    trials = cleanup_trials(cmu_walk, "cmu", JOINTS, seed=0, slides_cm=(5.0,))
    assert len(trials) == 8
    assert all(t.upper_body_changed == 0 for t in trials)
    assert all(t.hip_knee_deg_outside == 0.0 for t in trials)
    assert np.median([t.injected_cm for t in trials]) > 3.0
    assert np.median([t.fixed_cm for t in trials]) <= 0.5
    # Checked at the joints, the residual "at the joints" is the same reading.
    assert [t.fixed_joints_cm for t in trials] == [t.fixed_cm for t in trials]


def test_a_skate_over_two_contacts_locks_the_one_whose_confidence_it_carries() -> None:
    contacts = [Contact("right", 144, 154, 0.497), Contact("right", 162, 230, 0.803)]
    skate = Finding("skate", "right", 141, 211, 3.0, 180)
    assert finding_confidence(skate, contacts) == 0.803
    assert choose_locks("confident", contacts, [skate]) == [contacts[1]]
    assert choose_locks("skate-right-141", contacts, [skate]) == [contacts[1]]
    assert locked_findings("confident", contacts, [skate]) == {"skate-right-141"}
    # Overlapping no contact, the lock holds the finding's own frames.
    alone = Finding("skate", "left", 10, 20, 2.0, 15)
    assert choose_locks("skates", contacts, [alone]) == [Contact("left", 10, 20, 0.0)]
