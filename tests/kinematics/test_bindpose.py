"""Bind-pose first frames: found on the corpus takes that have one, and left out of filtering
and twist detection."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.filters.apply import filter_motion
from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.twist.analysis import detect_chains
from mocapqa.twist.angles import chain_geometry

# The corpus README lists these as starting with a T-pose frame.
WITH_BIND_POSE = {"cmu_12_01_walk.bvh", "007_04.bvh", "007_12.bvh"}


def test_the_bind_pose_frames_of_the_corpus_are_found_and_no_others(bvh_files: list[Path]) -> None:
    found = {p.name for p in bvh_files if leading_bind_pose(read_bvh(p).quats) == 1}
    assert found == WITH_BIND_POSE


def test_short_and_still_takes_have_none() -> None:
    still = np.zeros((10, 3, 4))
    still[..., 3] = 1.0
    assert leading_bind_pose(still) == 0
    assert leading_bind_pose(still[:2]) == 0


def test_a_filter_starts_on_the_motion_and_keeps_the_bind_pose_frame(cmu_walk: Path) -> None:
    walk = read_bvh(cmu_walk)
    filtered = filter_motion(walk, "quat-pd")
    assert np.array_equal(filtered.quats[0], walk.quats[0])
    assert np.array_equal(filtered.translations[0], walk.translations[0])
    hint = None if walk.euler_hint_deg is None else walk.euler_hint_deg[1:]
    motion_only = dataclasses.replace(
        walk, quats=walk.quats[1:], translations=walk.translations[1:], euler_hint_deg=hint
    )
    assert np.allclose(filtered.quats[1:], filter_motion(motion_only, "quat-pd").quats)


def test_twist_detection_gives_the_step_into_the_motion_no_increment(cmu_walk: Path) -> None:
    walk = read_bvh(cmu_walk)
    chains = tuple(chain_geometry(walk.skeleton, c) for c in limb_chains(find_roles(walk.skeleton)))
    detection = detect_chains(walk.quats, chains, walk.fps)
    assert np.all(detection.parent_increments[1] == 0.0)
    assert np.all(detection.child_increments[1] == 0.0)
    assert np.any(detection.parent_increments[2] != 0.0)
