"""Detection and refinement on real takes with injected errors, and on clean takes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocapqa.core.motion import Motion
from mocapqa.errors import InputError, ShapeError
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.metrics.twist import clean_change, rotation_errors_deg, twist_accuracy
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.angles import chain_geometry
from mocapqa.twist.detect import PaperParams, RobustParams
from mocapqa.twist.inject import inject_twist_errors
from mocapqa.twist.refine import refine_quats

RIGS = ["cmu", "iclone", "bandai"]


@pytest.mark.parametrize("rig", RIGS)
def test_robust_finds_and_removes_injected_errors(takes: dict[str, Motion], rig: str) -> None:
    motion = takes[rig]
    before: list[np.ndarray] = []
    after: list[np.ndarray] = []
    for seed in range(3):
        corrupted, truth = inject_twist_errors(motion, np.random.default_rng(seed))
        analysis = analyze_twist(corrupted)
        mask = truth.error_mask
        before.append(rotation_errors_deg(truth.clean_quats[mask], corrupted.quats[mask]))
        after.append(rotation_errors_deg(truth.clean_quats[mask], analysis.refined.quats[mask]))
        found = {(i.joint, i.start_frame, i.end_frame) for i in analysis.intervals}
        hits = sum((i.joint, i.start_frame, i.end_frame) in found for i in truth.intervals)
        assert hits >= 0.8 * len(truth.intervals)
    accuracy = twist_accuracy(np.concatenate(before), np.concatenate(after))
    assert accuracy.fsr >= 0.9
    assert accuracy.mae_after_deg <= 0.1 * accuracy.mae_before_deg


@pytest.mark.parametrize("rig", RIGS)
def test_robust_leaves_clean_takes_unchanged(takes: dict[str, Motion], rig: str) -> None:
    motion = takes[rig]
    refined = analyze_twist(motion).refined
    change = clean_change(motion.quats, refined.quats, tolerance_deg=1.0)
    assert change.share <= 0.001


def test_paper_method_reduces_the_error_and_changes_clean_takes_more(
    takes: dict[str, Motion],
) -> None:
    motion = takes["cmu"]
    corrupted, truth = inject_twist_errors(motion, np.random.default_rng(1))
    refined = analyze_twist(corrupted, "paper").refined
    mask = truth.error_mask
    before = rotation_errors_deg(truth.clean_quats[mask], corrupted.quats[mask])
    after = rotation_errors_deg(truth.clean_quats[mask], refined.quats[mask])
    assert after.mean() < 0.5 * before.mean()
    paper_clean = clean_change(motion.quats, analyze_twist(motion, "paper").refined.quats)
    robust_clean = clean_change(motion.quats, analyze_twist(motion).refined.quats)
    assert paper_clean.n_changed >= robust_clean.n_changed


@pytest.mark.parametrize("method", ["robust", "paper"])
def test_refine_touches_only_corrected_pairs_and_keeps_child_orientation(
    takes: dict[str, Motion], method: str
) -> None:
    motion = takes["iclone"]
    corrupted, _ = inject_twist_errors(motion, np.random.default_rng(4))
    analysis = analyze_twist(corrupted, method)
    assert analysis.intervals
    corrected = {
        j
        for c, g in enumerate(analysis.chains)
        if np.any(analysis.offsets_rad[:, c] != 0.0)
        for j in (g.chain.parent, g.chain.child, *g.children)
    }
    outside = [j for j in range(motion.skeleton.n_joints) if j not in corrected]
    assert np.array_equal(analysis.refined.quats[:, outside], corrupted.quats[:, outside])
    assert np.array_equal(analysis.refined.translations, corrupted.translations)
    world_before, _ = forward_kinematics(corrupted)
    world_after, _ = forward_kinematics(analysis.refined)
    # Children of corrected chains, except those that are themselves a corrected parent.
    corrected_parents = {
        g.chain.parent
        for c, g in enumerate(analysis.chains)
        if np.any(analysis.offsets_rad[:, c] != 0.0)
    }
    children = [
        g.chain.child
        for c, g in enumerate(analysis.chains)
        if np.any(analysis.offsets_rad[:, c] != 0.0) and g.chain.child not in corrected_parents
    ]
    assert children
    a, b = world_before[:, children], world_after[:, children]
    difference = np.minimum(np.abs(a - b).max(axis=-1), np.abs(a + b).max(axis=-1))
    assert np.max(difference) < 1e-9


def test_refine_quats_removes_a_known_offset_like_scipy(takes: dict[str, Motion]) -> None:
    motion = takes["bandai"]
    skeleton = motion.skeleton
    from mocapqa.core.rig import find_roles, limb_chains

    geometry = chain_geometry(skeleton, limb_chains(find_roles(skeleton))[1])
    offsets = np.zeros((motion.n_frames, 1))
    offsets[10:20, 0] = 0.7
    refined = refine_quats(motion.quats, [geometry], offsets)
    parent = geometry.chain.parent
    expected = (
        Rotation.from_quat(motion.quats[10:20, parent]) * Rotation.from_rotvec(-0.7 * geometry.axis)
    ).as_quat()
    np.testing.assert_allclose(
        Rotation.from_quat(refined[10:20, parent]).as_matrix(),
        Rotation.from_quat(expected).as_matrix(),
        atol=1e-12,
    )
    assert np.array_equal(refined[:10], motion.quats[:10])
    with pytest.raises(ShapeError, match="Expected `offsets_rad` to have shape"):
        refine_quats(motion.quats, [geometry], offsets[:5])


def test_unknown_method_and_wrong_parameters_are_rejected(takes: dict[str, Motion]) -> None:
    with pytest.raises(InputError, match="Expected method in"):
        analyze_twist(takes["cmu"], "magic")
    with pytest.raises(InputError, match="Expected RobustParams"):
        analyze_twist(takes["cmu"], "robust", params=PaperParams())
    with pytest.raises(InputError, match="Expected child_source"):
        RobustParams(child_source="elbow")


def test_helper_joints_between_parent_and_child_are_composed_and_kept(
    takes: dict[str, Motion],
) -> None:
    motion = takes["cmu"]
    skeleton = motion.skeleton
    # Map the clavicle chain's child to the forearm, so the upper arm sits between them.
    mapping = {
        "LeftShoulder": "left_clavicle",
        "LeftForeArm": "left_upper_arm",
        "LeftHand": "left_forearm",
    }
    from mocapqa.core.rig import find_roles, limb_chains

    chains = [c for c in limb_chains(find_roles(skeleton, mapping)) if c.side == "left"]
    chain = next(c for c in chains if c.segment == "clavicle")
    geometry = chain_geometry(skeleton, chain)
    assert geometry.intermediates == (skeleton.index("LeftArm"),)
    offsets = np.zeros((motion.n_frames, 1))
    offsets[200:212, 0] = -np.deg2rad(60.0)
    corrupted_quats = refine_quats(motion.quats, [geometry], offsets)
    # The helper between parent and child is counter-rotated; the child's local rotation is
    # kept, and every joint below the parent keeps its world orientation.
    child = skeleton.index("LeftForeArm")
    helper = skeleton.index("LeftArm")
    assert np.array_equal(corrupted_quats[:, child], motion.quats[:, child])
    world_before, _ = forward_kinematics(motion)
    corrupted = Motion(skeleton, corrupted_quats, motion.translations, motion.fps)
    world_after, _ = forward_kinematics(corrupted)
    below = [
        j for j in range(skeleton.n_joints) if j > helper and j != skeleton.index("LeftShoulder")
    ]
    a, b = world_before[:, below], world_after[:, below]
    assert np.max(np.minimum(np.abs(a - b).max(-1), np.abs(a + b).max(-1))) < 1e-9
    analysis = analyze_twist(corrupted, mapping=mapping)
    found = [i for i in analysis.intervals if i.joint == "LeftShoulder"]
    assert [(i.start_frame, i.end_frame) for i in found] == [(200, 211)]
    assert found[0].offset_deg == pytest.approx(60.0, abs=1.0)
    restored = analysis.refined.quats[:, [skeleton.index("LeftShoulder"), helper]]
    expected = motion.quats[:, [skeleton.index("LeftShoulder"), helper]]
    assert (
        np.max(np.minimum(np.abs(restored - expected).max(-1), np.abs(restored + expected).max(-1)))
        < 0.02
    )
