"""The synthetic injection protocol on real takes."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import geodesic_angle
from mocapqa.twist.inject import _cluster_parts, inject_twist_errors

LIMB = {"clavicle": "arm", "upper_arm": "arm", "forearm": "arm", "upper_leg": "leg",
        "lower_leg": "leg"}  # fmt: skip


@pytest.mark.parametrize("rig", ["cmu", "iclone", "bandai"])
def test_injection_follows_the_protocol(takes: dict[str, Motion], rig: str) -> None:
    motion = takes[rig]
    corrupted, truth = inject_twist_errors(motion, np.random.default_rng(11))
    assert len(truth.targets) == 2
    limbs = {
        (side, LIMB[segment]) for side, segment in zip(truth.sides, truth.segments, strict=True)
    }
    assert len(limbs) == 2
    for target in truth.targets:
        mine = [i for i in truth.intervals if i.joint == motion.skeleton.names[target]]
        assert 2 <= len(mine) <= 5
        for interval in mine:
            assert 1 <= interval.end_frame - interval.start_frame + 1 <= 20
            assert 5.0 <= abs(interval.offset_deg) <= 180.0
            rows = slice(interval.start_frame, interval.end_frame + 1)
            error = np.rad2deg(
                geodesic_angle(motion.quats[rows, target], corrupted.quats[rows, target])
            )
            np.testing.assert_allclose(error, abs(interval.offset_deg), atol=1e-6)
    changed = np.any(corrupted.quats != motion.quats, axis=-1)
    allowed = np.zeros_like(changed)
    # The target and every direct child of it (the role child and helper bones).
    parents = motion.skeleton.parents
    below = [j for j in range(len(parents)) if parents[j] in truth.targets]
    assert set(truth.children) <= set(below)
    allowed[:, list(truth.targets) + below] = True
    assert not np.any(changed & ~allowed)
    assert np.array_equal(changed[:, list(truth.targets)], truth.error_mask[:, list(truth.targets)])


def test_injection_keeps_every_child_global_orientation(takes: dict[str, Motion]) -> None:
    motion = takes["cmu"]
    corrupted, truth = inject_twist_errors(motion, np.random.default_rng(5))
    world_before, positions_before = forward_kinematics(motion)
    world_after, positions_after = forward_kinematics(corrupted)
    others = [j for j in range(motion.skeleton.n_joints) if j not in truth.targets]
    a, b = world_before[:, others], world_after[:, others]
    difference = np.minimum(np.abs(a - b).max(axis=-1), np.abs(a + b).max(axis=-1))
    assert np.max(difference) < 1e-9
    # A twist about the bone moves no joint: R(a, δ) a = a.
    np.testing.assert_allclose(positions_after, positions_before, atol=1e-9)
    targets = list(truth.targets)
    assert np.max(geodesic_angle(world_before[:, targets], world_after[:, targets])) > 0.08


def test_injection_is_reproducible_with_a_seed(takes: dict[str, Motion]) -> None:
    a, truth_a = inject_twist_errors(takes["bandai"], np.random.default_rng(7))
    b, truth_b = inject_twist_errors(takes["bandai"], np.random.default_rng(7))
    c, _ = inject_twist_errors(takes["bandai"], np.random.default_rng(8))
    assert np.array_equal(a.quats, b.quats)
    assert truth_a.intervals == truth_b.intervals
    assert not np.array_equal(a.quats, c.quats)


def test_offset_range_parameters_are_respected(takes: dict[str, Motion]) -> None:
    _, truth = inject_twist_errors(
        takes["cmu"], np.random.default_rng(2), min_offset_deg=30.0, max_offset_deg=40.0
    )
    assert all(30.0 <= abs(i.offset_deg) <= 40.0 for i in truth.intervals)


def test_bad_offset_range_is_rejected(takes: dict[str, Motion]) -> None:
    with pytest.raises(InputError, match="Expected 0 < min_offset_deg"):
        inject_twist_errors(takes["cmu"], np.random.default_rng(0), min_offset_deg=50.0,
                            max_offset_deg=10.0)  # fmt: skip


@pytest.mark.parametrize("rig", ["iclone", "bandai"])
def test_clusters_are_separate_errors_close_together(takes: dict[str, Motion], rig: str) -> None:
    motion = takes[rig]
    fps = motion.fps
    corrupted, truth = inject_twist_errors(motion, np.random.default_rng(4), kind="cluster")
    assert len(truth.targets) == 2
    gaps = []
    for target in truth.targets:
        mine = sorted(
            (i for i in truth.intervals if i.joint == motion.skeleton.names[target]),
            key=lambda i: i.start_frame,
        )
        assert len(mine) >= 2
        for interval in mine:
            length = interval.end_frame - interval.start_frame + 1
            assert 1 <= length <= max(2, round(0.15 * fps))
            assert 20.0 <= abs(interval.offset_deg) <= 90.0
            rows = slice(interval.start_frame, interval.end_frame + 1)
            error = np.rad2deg(
                geodesic_angle(motion.quats[rows, target], corrupted.quats[rows, target])
            )
            np.testing.assert_allclose(error, abs(interval.offset_deg), atol=1e-6)
        gaps += [b.start_frame - a.end_frame - 1 for a, b in pairwise(mine)]
        # Each piece is an error of its own: the roll is natural between them.
        assert np.array_equal(
            truth.error_mask[:, target],
            np.isin(np.arange(motion.n_frames),
                    [f for i in mine for f in range(i.start_frame, i.end_frame + 2 - 1)]),
        )  # fmt: skip
    assert min(gaps) >= 1


@pytest.mark.parametrize("fps", [30.0, 60.0, 120.0])
def test_cluster_pieces_are_one_frame_to_a_third_of_a_second_apart(fps: float) -> None:
    rng = np.random.default_rng(0)
    counts = []
    for _ in range(200):
        start, end = 10, 10 + int(rng.integers(0, round(0.6 * fps)))
        parts = _cluster_parts(rng, start, end, fps)
        counts.append(len(parts))
        assert parts[0][0] == start
        assert all(start <= a <= b <= end for a, b, _ in parts)
        for (_, b, _), (a, _, _) in pairwise(parts):
            assert 1 <= a - b - 1 <= round(0.3 * fps)
        assert all(b - a + 1 <= round(0.15 * fps) for a, b, _ in parts)
        assert all(20.0 <= abs(v) <= 90.0 for _, _, v in parts)
    assert max(counts) == 4
    assert min(counts) == 1
    assert np.mean(np.array(counts) >= 2) > 0.4


def test_cluster_children_counter_rotate_up_to_a_mismatch(takes: dict[str, Motion]) -> None:
    motion = takes["iclone"]
    corrupted, truth = inject_twist_errors(motion, np.random.default_rng(9), kind="cluster")
    world_before, _ = forward_kinematics(motion)
    world_after, _ = forward_kinematics(corrupted)
    for target, child in zip(truth.targets, truth.children, strict=True):
        rows = truth.error_mask[:, target]
        moved = np.rad2deg(geodesic_angle(world_before[rows, child], world_after[rows, child]))
        offsets = np.abs(np.rad2deg(truth.offsets_rad[rows, target]))
        # The child's world orientation moves by ε δ with |ε| ≤ 0.2, never by the offset.
        assert np.all(moved <= 0.2 * offsets + 1e-6)
        clean = ~rows
        assert np.max(geodesic_angle(world_before[clean, child], world_after[clean, child])) < 1e-9
