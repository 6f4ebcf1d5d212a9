"""Twist errors at a take's ends: one-sided intervals and bind-pose first frames, on real takes."""

from __future__ import annotations

from dataclasses import replace
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.io.bvh import read_bvh
from mocapqa.metrics.twist import rotation_errors_deg
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.angles import ChainGeometry, chain_geometry
from mocapqa.twist.confidence import END_MAX_MISMATCH, END_MIN_LEVEL_DEG, decide
from mocapqa.twist.detect import RobustParams, leading_pose_frames
from mocapqa.twist.inject import inject_twist_errors
from mocapqa.twist.intervals import FEATURES
from mocapqa.twist.refine import refine_quats

OFFSET_DEG = 40.0


def _chain(motion: Motion, segment: str, side: str = "left") -> ChainGeometry:
    chains = limb_chains(find_roles(motion.skeleton))
    chain = next(c for c in chains if c.segment == segment and c.side == side)
    return chain_geometry(motion.skeleton, chain)


def _with_offset(motion: Motion, geometry: ChainGeometry, rows: slice) -> Motion:
    """The take with a twist offset of ``OFFSET_DEG`` on ``rows`` of one chain (child
    compensated, as the injection does)."""
    offsets = np.zeros((motion.n_frames, 1))
    offsets[rows] = np.deg2rad(OFFSET_DEG)
    return replace(motion, quats=refine_quats(motion.quats, (geometry,), -offsets))


def _prepend(motion: Motion, frames: int) -> Motion:
    """The take with ``frames`` copies of the rest pose (identity rotations) before it."""
    pose = np.zeros((frames, *motion.quats.shape[1:]))
    pose[..., 0] = 1.0
    return replace(
        motion,
        quats=np.concatenate([pose, motion.quats]),
        translations=np.concatenate([np.repeat(motion.translations[:1], frames, 0),
                                     motion.translations]),
        euler_hint_deg=None,
    )  # fmt: skip


@pytest.mark.parametrize("where", ["tail", "head"])
@pytest.mark.parametrize("segment", ["lower_leg", "upper_arm"])
def test_an_error_at_an_end_of_a_real_take_is_corrected(
    takes: dict[str, Motion], where: str, segment: str
) -> None:
    for rig, motion in takes.items():
        geometry = _chain(motion, segment, "right")
        n, first = motion.n_frames, leading_pose_frames(motion.quats)
        length = round(0.2 * motion.fps)
        rows = slice(n - length, n) if where == "tail" else slice(first, first + length)
        analysis = analyze_twist(_with_offset(motion, geometry, rows))
        parent = geometry.chain.parent
        applied = [i for i in analysis.intervals if i.applied]
        assert [(i.joint, i.start_frame, i.end_frame) for i in applied] == [
            (motion.skeleton.names[parent], rows.start, rows.stop - 1)
        ], rig
        found = next(f for f in analysis.found if f.start_frame == rows.start)
        assert found.side == where
        left = rotation_errors_deg(motion.quats[rows, parent], analysis.refined.quats[rows, parent])
        assert left.max() < 0.1 * OFFSET_DEG, rig
        # The child keeps its world pose, so its local rotation takes the offset back.
        outside = np.ones(n, dtype=bool)
        outside[rows] = False
        assert np.array_equal(analysis.refined.quats[outside], motion.quats[outside]), rig


@pytest.mark.parametrize(
    "path",
    [
        "bvh/cmu/cmu_12_01_walk.bvh",
        "bvh/cmu/iclone/002_09.bvh",
        "bvh/bandai/dataset-2_walk_normal_001.bvh",
        # A kicking arm rolls 2–9° per frame with the forearm rolling back, and a raised arm
        # ends on a 14° counter-rotated step: natural steps near the ends that hold.
        "bvh/bandai/dataset-1_kick_normal_001.bvh",
        "bvh/bandai/dataset-2_raise-up-right-hand_youthful_001.bvh",
    ],
)
def test_a_clean_real_take_gets_no_interval_at_its_ends(corpus_dir: Path, path: str) -> None:
    analysis = analyze_twist(read_bvh(corpus_dir / path))
    assert [f for f in analysis.found if f.side] == []
    assert not any(i.applied for i in analysis.intervals)


def test_the_injected_end_intervals_touch_the_ends(takes: dict[str, Motion]) -> None:
    motion = takes["bandai"]
    for where in ("tail", "head"):
        for seed in range(3):
            _, truth = inject_twist_errors(motion, np.random.default_rng(seed), ends=where)
            for target in truth.targets:
                mine = [i for i in truth.intervals if i.joint == motion.skeleton.names[target]]
                if where == "tail":
                    assert max(i.end_frame for i in mine) == motion.n_frames - 1
                else:
                    assert min(i.start_frame for i in mine) == 0
                spans = sorted((i.start_frame, i.end_frame) for i in mine)
                assert all(b[0] > a[1] + 1 for a, b in pairwise(spans))


@pytest.mark.parametrize("frames", [1, 3])
def test_a_prepended_bind_pose_changes_nothing_on_the_rest(
    takes: dict[str, Motion], frames: int
) -> None:
    motion = takes["iclone"]
    n = motion.n_frames
    geometry = _chain(motion, "lower_leg", "right")
    length = round(0.2 * motion.fps)
    broken = _with_offset(motion, geometry, slice(0, length))
    broken = _with_offset(broken, _chain(motion, "upper_arm"), slice(n - length, n))
    posed = _prepend(broken, frames)
    assert leading_pose_frames(broken.quats) == 0
    assert leading_pose_frames(posed.quats) == frames
    plain, shifted = analyze_twist(broken), analyze_twist(posed)
    assert [(i.joint, i.start_frame + frames, i.end_frame + frames, i.offset_deg, i.applied)
            for i in plain.intervals] == [
        (i.joint, i.start_frame, i.end_frame, i.offset_deg, i.applied) for i in shifted.intervals
    ]  # fmt: skip
    assert len([i for i in plain.intervals if i.applied]) == 2
    assert np.array_equal(shifted.refined.quats[frames:], plain.refined.quats)
    assert np.array_equal(shifted.refined.quats[:frames], posed.quats[:frames])


def test_the_cmu_walks_bind_pose_frame_is_not_the_reference(takes: dict[str, Motion]) -> None:
    walk = takes["cmu"]
    assert leading_pose_frames(walk.quats) == 1
    rest = replace(
        walk, quats=walk.quats[1:], translations=walk.translations[1:], euler_hint_deg=None
    )
    geometry = _chain(walk, "lower_leg")
    length = round(0.2 * walk.fps)
    with_pose = analyze_twist(_with_offset(walk, geometry, slice(1, 1 + length)))
    without = analyze_twist(_with_offset(rest, geometry, slice(0, length)))
    assert [(i.start_frame - 1, i.end_frame - 1, i.offset_deg) for i in with_pose.intervals] == [
        (i.start_frame, i.end_frame, i.offset_deg) for i in without.intervals
    ]
    assert np.array_equal(with_pose.refined.quats[1:], without.refined.quats)


def test_an_interior_shift_whose_release_made_no_event_is_not_corrected_to_an_end(
    corpus_dir: Path,
) -> None:
    # A 7° shift of a Bandai knee over frames 16–34: its onset is an event, its release at 35
    # is not (the fit-take injection that read the onset as a head's release and moved the
    # clean frames 0–15 by 7°). The roll steps back over the stretch a head would leave
    # natural, so no one-sided interval forms and no clean frame moves.
    motion = read_bvh(corpus_dir / "bvh/bandai/dataset-1_run_giant_001.bvh")
    geometry = _chain(motion, "lower_leg", "right")
    offsets = np.zeros((motion.n_frames, 1))
    offsets[16:35] = np.deg2rad(7.0)
    shifted = replace(motion, quats=refine_quats(motion.quats, (geometry,), -offsets))
    clean = np.ones(motion.n_frames, dtype=bool)
    clean[16:35] = False
    parent = geometry.chain.parent
    without = analyze_twist(shifted, params=RobustParams(end_return=0.0))
    assert [(f.side, f.start_frame, f.end_frame) for f in without.found] == [("head", 0, 15)]
    moved = rotation_errors_deg(motion.quats[clean, parent], without.refined.quats[clean, parent])
    assert moved.max() > 5.0
    analysis = analyze_twist(shifted)
    assert not [f for f in analysis.found if f.side]
    assert np.array_equal(analysis.refined.quats[clean], motion.quats[clean])


def test_a_small_one_sided_interval_with_an_inexact_counter_rotation_is_reported_not_applied() -> (
    None
):
    level = FEATURES.index("log_level_deg")
    mismatch = FEATURES.index("mismatch")
    base = [5.0, 0.0, 0.0, 0.0, -1.0, float(np.log(14.0)), 0.0, 0.0]
    inexact = list(base)
    inexact[mismatch] = 0.1
    large = list(inexact)
    large[level] = float(np.log(END_MIN_LEVEL_DEG))
    features = [inexact, inexact, base, large]
    applied, rules = decide(np.ones(4), features, None, sides=["head", "", "tail", "tail"])
    assert applied.tolist() == [False, True, True, True]
    assert rules[0] == "end_evidence"
    assert END_MAX_MISMATCH < 0.1


@pytest.mark.parametrize(
    ("take", "segment", "side", "where"),
    [
        ("bvh/cmu/iclone/005_16.bvh", "upper_arm", "right", "head"),
        ("bvh/bandai/dataset-2_wave-both-hands_youthful_001.bvh", "forearm", "left", "tail"),
    ],
)
def test_a_shift_one_frame_from_an_end_whose_step_back_made_no_event_moves_no_clean_frame(
    corpus_dir: Path, take: str, segment: str, side: str, where: str
) -> None:
    # A 35° shift over frames 1–24 (head) or over the 16 frames before the last (tail) of a fit
    # take: its event next to the end reads, locally, as a one-frame head's release (a tail's
    # onset); its other end made no event, and the parent and the child step back by the jump
    # from one frame to the next, while their levels averaged over ``burst_gap_s`` frames do not
    # (the other roll moves fast there). No one-sided interval forms, the end frame is left.
    motion = read_bvh(corpus_dir / take)
    geometry = _chain(motion, segment, side)
    rows = slice(1, 25) if where == "head" else slice(motion.n_frames - 17, motion.n_frames - 1)
    offsets = np.zeros((motion.n_frames, 1))
    offsets[rows] = np.deg2rad(35.0)
    shifted = replace(motion, quats=refine_quats(motion.quats, (geometry,), -offsets))
    clean = np.ones(motion.n_frames, dtype=bool)
    clean[rows] = False
    end = 0 if where == "head" else motion.n_frames - 1
    without = analyze_twist(shifted, params=RobustParams(end_return=0.0))
    assert [(f.side, f.start_frame, f.end_frame) for f in without.found if f.side] == [
        (where, end, end)
    ]
    analysis = analyze_twist(shifted)
    assert not [f for f in analysis.found if f.side]
    assert np.array_equal(analysis.refined.quats[clean], motion.quats[clean])
