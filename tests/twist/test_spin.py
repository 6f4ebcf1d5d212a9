"""Limb spins and flips: found where a retarget makes them, nowhere on clean takes, not applied."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles
from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import conjugate, multiply, quats_from_axis_angle
from mocapqa.kinematics.resample import resample_motion
from mocapqa.pipeline.steps import run_twist
from mocapqa.twist.spin import find_limb_spins

SUBJECT_005 = ("005_03.bvh", "005_05.bvh", "005_11.bvh", "005_12.bvh", "005_16.bvh")
"""Character Creator dance takes of CMU subject 005: the retarget spins their right arms."""


def spin_limb(
    motion: Motion, side: str, limb: tuple[str, str, str], turns_deg: np.ndarray, keep_end: bool
) -> Motion:
    """``motion`` with a limb's upper segment turned about the limb axis (root → end joint) by
    ``turns_deg[f]`` on frame f, its middle segment following and its end segment kept in
    place (``keep_end``) or turned along."""
    rig = find_roles(motion.skeleton)
    upper, middle, end = (rig.joint(side, role) for role in limb)  # type: ignore[arg-type]
    assert upper is not None
    assert middle is not None
    assert end is not None
    world, positions = forward_kinematics(motion)
    axes = positions[:, end] - positions[:, upper]
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    turn = quats_from_axis_angle(axes, np.deg2rad(turns_deg))
    quats = motion.quats.copy()
    parent = motion.skeleton.parents[upper]
    new_upper = multiply(turn, world[:, upper])
    quats[:, upper] = multiply(conjugate(world[:, parent]), new_upper)
    if keep_end:
        new_middle = multiply(turn, world[:, middle])
        quats[:, end] = multiply(conjugate(new_middle), world[:, end])
    return replace(motion, quats=quats)


@pytest.fixture(scope="module")
def walk(corpus_dir: Path) -> Motion:
    """A clean Character Creator walk at 60 fps (no bind pose in its first frame)."""
    return read_bvh(corpus_dir / "bvh/cmu/iclone/003_02.bvh")


def test_a_straight_arm_spin_is_found_with_its_frames_and_roll(walk: Motion) -> None:
    assert find_limb_spins(walk) == []
    turns = np.zeros(walk.n_frames)
    turns[60:] = 90.0
    turns[60:63] = [30.0, 60.0, 90.0]  # 30° per frame at 60 fps: 1,800°/s
    spun = spin_limb(walk, "right", ("upper_arm", "forearm", "hand"), turns, keep_end=True)
    # The hand's world pose does not move: only the upper arm and forearm roll.
    before, after = forward_kinematics(walk), forward_kinematics(spun)
    hand = find_roles(walk.skeleton).joint("right", "hand")
    np.testing.assert_allclose(after[1][:, hand], before[1][:, hand], atol=1e-6)
    [spin] = find_limb_spins(spun)
    assert (spin.side, spin.limb, spin.shape) == ("right", "arm", "spin")
    assert (spin.start_frame, spin.end_frame) == (60, 62)
    assert spin.roll_deg == pytest.approx(90.0, abs=5.0)
    assert abs(spin.end_roll_deg) < 5.0
    assert "right arm spun" in spin.readout()
    assert "not corrected" in spin.readout()


def test_a_whole_leg_flip_for_one_frame_is_one_flip_and_back(walk: Motion) -> None:
    turns = np.zeros(walk.n_frames)
    turns[80] = 175.0
    flipped = spin_limb(walk, "left", ("upper_leg", "lower_leg", "foot"), turns, keep_end=False)
    [flip] = find_limb_spins(flipped)
    assert (flip.side, flip.limb, flip.shape) == ("left", "leg", "flip")
    assert (flip.start_frame, flip.end_frame) == (80, 81)
    assert abs(flip.value_deg) == pytest.approx(175.0, abs=5.0)
    assert "knee to the other side" in flip.readout()


def test_spins_are_found_alike_after_resampling(walk: Motion) -> None:
    """Rates are per second: the spin of a 60 fps take is found at 30 and 120 fps."""
    turns = np.zeros(walk.n_frames)
    turns[60:] = 90.0
    turns[60:63] = [30.0, 60.0, 90.0]
    spun = spin_limb(walk, "right", ("upper_arm", "forearm", "hand"), turns, keep_end=True)
    for fps in (30.0, 120.0):
        found = find_limb_spins(resample_motion(spun, fps))
        assert [(s.side, s.limb, s.shape) for s in found] == [("right", "arm", "spin")]
        assert found[0].start_frame / fps == pytest.approx(60 / walk.fps, abs=2 / fps)
        assert found[0].roll_deg == pytest.approx(90.0, abs=10.0)


def test_the_corpus_spins_are_subject_005s_arms_and_legs(bvh_files: list[Path]) -> None:
    """No take of another performer or rig has a spin or flip, except the climbing take's
    hanging arm (001_14); subject 005's right arm spins in every one of its takes, and
    005_03's spins 184° in frames 26–30 while the hand turns 7°."""
    spun = {}
    for path in bvh_files:
        motion = read_bvh(path)
        spins = find_limb_spins(motion)
        if spins:
            spun[path.name] = spins
    assert set(spun) == {"001_14.bvh", *SUBJECT_005}
    for name in SUBJECT_005:
        assert any((s.side, s.limb) == ("right", "arm") for s in spun[name])
    big = next(s for s in spun["005_03.bvh"] if s.start_frame == 26)
    assert (big.end_frame, big.shape) == (30, "spin")
    assert big.roll_deg == pytest.approx(-184, abs=2)
    assert abs(big.end_roll_deg) < 10


def test_the_twist_step_reports_spins_without_applying_them(corpus_dir: Path) -> None:
    motion = read_bvh(corpus_dir / "bvh/cmu/iclone/005_03.bvh")
    outcome = run_twist(motion, "robust")
    spins = [f for f in outcome.findings if f["kind"] == "spin"]
    assert len(spins) == len(find_limb_spins(motion)) >= 1
    assert all(f["confidence"] is None and "not corrected" in f["readout"] for f in spins)
    assert "limb spin(s) reported, not corrected" in outcome.message
    # The corrected take is the twist step's own: no interval applied on 005_03, no change.
    twist = [f for f in outcome.findings if f["kind"] == "twist"]
    if not any(f["applied"] for f in twist):
        assert outcome.motion is not None
        np.testing.assert_array_equal(outcome.motion.quats, motion.quats)
