"""Scene preparation on real takes: up axes, bones, layouts and camera framing (no OpenGL)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ShapeError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.formats import read_take
from mocapqa.render.layouts import bones_for_keypoints
from mocapqa.render.scene import (
    SkeletonTrack,
    bones_from_parents,
    detect_up_axis,
    frame_camera,
    track_from_keypoints,
    track_from_motion,
    track_from_points,
    up_vector,
)

MEDIAPIPE = "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv"
TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


@pytest.mark.parametrize(
    ("relative", "expected"),
    [
        # Up axes as documented in the corpus README.
        ("bvh/cmu/cmu_12_01_walk.bvh", "+y"),
        ("bvh/bandai/dataset-1_kick_normal_001.bvh", "+y"),
        ("bvh/misc/bvh_example.bvh", "+z"),
        ("bvh/misc/bvh_test3.bvh", "+z"),
    ],
)
def test_up_axis_of_bvh_takes_matches_corpus_notes(
    corpus_dir: Path, relative: str, expected: str
) -> None:
    track = track_from_motion(read_bvh(corpus_dir / relative))
    assert track.up_axis == expected


def test_mediapipe_world_landmarks_are_y_down(corpus_dir: Path) -> None:
    sequence = read_take(corpus_dir / MEDIAPIPE)
    assert isinstance(sequence, KeypointSequence)
    track = track_from_keypoints(sequence)
    assert track.up_axis == "-y"
    assert len(track.bones) >= 30


def test_trc_markers_get_body_25b_bones(corpus_dir: Path) -> None:
    sequence = read_take(corpus_dir / TRC)
    assert isinstance(sequence, KeypointSequence)
    track = track_from_keypoints(sequence)
    pairs = {(track.names[a], track.names[b]) for a, b in track.bones}
    assert ("RHip", "RKnee") in pairs
    assert ("LElbow", "LWrist") in pairs
    assert track.up_axis == "+y"


def test_unknown_keypoint_names_draw_points_only() -> None:
    assert bones_for_keypoints(("a", "b", "c")).shape == (0, 2)


def test_zero_length_bones_are_dropped(cmu_walk: Path) -> None:
    motion = read_bvh(cmu_walk)
    track = track_from_motion(motion)
    names = motion.skeleton.names
    pairs = {(names[a], names[b]) for a, b in track.bones}
    # LHipJoint sits at the Hips (OFFSET 0 0 0), LeftUpLeg does not.
    assert ("Hips", "LHipJoint") not in pairs
    assert ("LHipJoint", "LeftUpLeg") in pairs
    lengths = np.linalg.norm(
        track.positions[:, track.bones[:, 1]] - track.positions[:, track.bones[:, 0]], axis=-1
    )
    assert np.all(lengths.max(axis=0) > 0)


def test_bones_from_parents_skips_roots() -> None:
    positions = np.array([[[0.0, 0, 0], [0, 1, 0], [0, 2, 0]]])
    bones = bones_from_parents(np.array([-1, 0, 1]), positions)
    assert bones.tolist() == [[0, 1], [1, 2]]


def test_camera_keeps_every_point_of_the_take_in_view(corpus_dir: Path) -> None:
    track = track_from_motion(read_bvh(corpus_dir / "bvh/cmu/cmu_12_01_walk.bvh"))
    aspect = 4 / 3
    camera = frame_camera(track, aspect=aspect)
    eye = np.array(camera.position)
    forward = np.array(camera.focal_point) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.array(camera.view_up))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    relative = track.positions.reshape(-1, 3) - eye
    depth = relative @ forward
    assert np.all(depth > 0)
    half_v = np.tan(np.radians(15.0))
    assert np.all(np.abs(relative @ up) / depth < half_v)
    assert np.all(np.abs(relative @ right) / depth < half_v * aspect)


def test_track_from_points_uses_layout_when_parents_are_all_roots(corpus_dir: Path) -> None:
    sequence = read_take(corpus_dir / TRC)
    assert isinstance(sequence, KeypointSequence)
    track = track_from_points(
        sequence.names, [-1] * len(sequence.names), sequence.positions, sequence.fps
    )
    assert len(track.bones) > 0


def test_detect_up_axis_falls_back_to_largest_extent() -> None:
    positions = np.zeros((2, 3, 3))
    positions[:, 1, 2] = 1.7
    assert detect_up_axis(positions, ("a", "b", "c")) == "+z"


def test_bad_up_axis_is_rejected() -> None:
    with pytest.raises(ShapeError, match="Expected `up_axis` in"):
        up_vector("up")


def test_track_rejects_out_of_range_bones() -> None:
    with pytest.raises(ShapeError, match="Expected bone indices"):
        SkeletonTrack(names=("a", "b"), positions=np.zeros((1, 2, 3)), bones=np.array([[0, 5]]))
