"""The feet check on real takes: the CMU walk (Y up), Z-up BVH takes, Pose2Sim TRC and
MediaPipe keypoints, and the corpus' rigs."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError
from mocapqa.io.bvh import parse_bvh, read_bvh
from mocapqa.io.formats import read_take
from mocapqa.pipeline.feet import check_take_feet, feet_report_json, keypoint_foot_points

POSE3D = "keypoints/pose2sim/{trial}/pose-3d/{trial}_{frames}.trc"
STATIC = POSE3D.format(trial="S00_P00_T00_StaticTrial", frames="0-12")
BALANCING = POSE3D.format(trial="S00_P00_T01_BalancingTrial", frames="0-100")
MEDIAPIPE = "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv"
ARMLESS_LEGLESS = (
    "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n"
    " JOINT Spine\n {\n  OFFSET 0 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
    "  End Site\n  {\n   OFFSET 0 10 0\n  }\n }\n}\nMOTION\nFrames: 3\n"
    "Frame Time: 0.04\n0 0 0 0 0 0\n0 0 0 0 0 0\n0 0 0 0 0 0\n"
)


@pytest.fixture(scope="module")
def walk_report(cmu_walk: Path) -> dict[str, Any]:
    points, report, skipped = check_take_feet(read_bvh(cmu_walk))
    return feet_report_json(points, report, skipped)


def test_the_cmu_walk_is_y_up_with_its_floor_under_the_toes(walk_report: dict[str, Any]) -> None:
    assert walk_report["up_axis"] == "Y"
    assert walk_report["up_axis_detail"]["method"] == "feet and body"
    # The toe joints rest at y ≈ 0.5–0.85 (the floor rises by ~0.58 units, 3.5 % of a leg,
    # along the 4.4 m walk, so it is reported tilted rather than levelled).
    assert 0.4 < walk_report["floor"] < 1.0
    check = walk_report["floor_check"]
    assert check["tilted"]
    assert not check["moving"]
    assert 0.3 < check["tilt_deg"] < 1.0
    assert walk_report["bind_pose_frames"] == 1  # frame 0 is the cgspeed T-pose
    assert walk_report["leg_length"] == pytest.approx(13.93, abs=0.05)


def test_the_cmu_walk_alternates_four_contacts_per_foot_and_does_not_skate(
    walk_report: dict[str, Any],
) -> None:
    contacts = walk_report["contacts"]
    assert [c["foot"] for c in contacts] == ["left", "right"] * 4
    starts = [c["start"] for c in contacts]
    assert starts == sorted(starts)
    assert contacts[0]["start"] == 1
    assert contacts[-1]["end"] == 523
    # One gait cycle (left strike to left strike) of a steady walk takes about 1.3 s.
    left = [c["start"] for c in contacts if c["foot"] == "left"]
    assert np.diff(left[1:]) / 120.0 == pytest.approx([1.28, 1.29], abs=0.05)
    # Double support: each contact overlaps the next foot's by a few frames.
    assert all(b["start"] <= a["end"] for a, b in itertools.pairwise(contacts))
    assert walk_report["findings"] == []
    assert walk_report["cm_per_unit"] is None  # a BVH does not store its unit


@pytest.mark.parametrize("name", ["bvh_example.bvh", "bvh_test3.bvh"])
def test_z_up_takes_are_found_z_up(corpus_dir: Path, name: str) -> None:
    _points, report, _ = check_take_feet(read_bvh(corpus_dir / "bvh" / "misc" / name))
    assert report.up.label == "Z"


def test_the_idle_z_up_take_stands_on_both_feet_throughout(corpus_dir: Path) -> None:
    motion = read_bvh(corpus_dir / "bvh" / "misc" / "bvh_test3.bvh")
    _, report, _ = check_take_feet(motion)
    assert [(c.foot, c.start, c.end) for c in report.contacts] == [
        ("left", 0, 99), ("right", 0, 99),
    ]  # fmt: skip
    assert report.findings == ()


def test_every_bvh_rig_of_the_corpus_stands_y_or_z_up(bvh_files: list[Path]) -> None:
    labels = {}
    for path in bvh_files:
        motion = read_bvh(path)
        if motion.n_frames < 10:
            continue
        labels[path.name] = check_take_feet(motion)[1].up.label
    z_up = {"bvh_example.bvh", "bvh_test3.bvh"}  # corpus README: Z up
    assert {n for n, label in labels.items() if label == "Z"} == z_up
    assert {label for n, label in labels.items() if n not in z_up} == {"Y"}


def test_a_bandai_walk_in_centimetres_has_clean_contacts(corpus_dir: Path) -> None:
    motion = read_bvh(
        corpus_dir / "bvh" / "bandai" / "dataset-1_walk_normal_001.bvh", length_unit="cm"
    )
    points, report, skipped = check_take_feet(motion)
    data = feet_report_json(points, report, skipped)
    assert data["cm_per_unit"] == 1.0
    assert data["sizes"] == "cm"
    assert data["leg_length_cm"] == pytest.approx(80.07, abs=0.05)
    # 6.5 s of walking at 30 fps: 13 alternating steps, nothing to report.
    assert len(data["contacts"]) == 13
    feet = [c["foot"] for c in data["contacts"]]
    assert all(a != b for a, b in itertools.pairwise(feet))
    assert data["findings"] == []
    assert abs(data["floor"]) < 5.0  # toes rest a few centimetres above y = 0


def test_the_pose2sim_static_trial_stands_on_its_floor(corpus_dir: Path) -> None:
    take = read_take(corpus_dir / STATIC)
    assert isinstance(take, KeypointSequence)
    points, report, _ = check_take_feet(take)
    data = feet_report_json(points, report)
    assert points.names == ("LHeel", "LBigToe", "RHeel", "RBigToe")
    assert data["up_axis"] == "Y"
    assert data["floor"] == pytest.approx(0.033, abs=0.002)  # big toes at y = 0.033 m
    assert data["cm_per_unit"] == 100.0
    assert [(c["foot"], c["start"], c["end"]) for c in data["contacts"]] == [
        ("left", 0, 11), ("right", 0, 11),
    ]  # fmt: skip
    assert data["findings"] == []


def test_the_pose2sim_balancing_trial_lifts_its_right_foot(corpus_dir: Path) -> None:
    take = read_take(corpus_dir / BALANCING)
    assert isinstance(take, KeypointSequence)
    _, report, _ = check_take_feet(take)
    assert report.up.label == "Y"
    left = [(c.start, c.end) for c in report.contacts if c.foot == "left"]
    right = [(c.start, c.end) for c in report.contacts if c.foot == "right"]
    # The left foot carries the balance; the right foot is down at the start and the end.
    assert len(left) == 1
    assert left[0][0] <= 1
    assert left[0][1] >= 75
    assert len(right) == 2
    assert right[0][0] == 0
    assert right[1][1] == 99
    assert 8 <= right[0][1] <= 16
    assert 72 <= right[1][0] <= 82


def test_mediapipe_world_landmarks_are_y_down(corpus_dir: Path) -> None:
    take = read_take(corpus_dir / MEDIAPIPE, fps=90.0)
    assert isinstance(take, KeypointSequence)
    points = keypoint_foot_points(take)
    assert points.parts == ("heel", "toe", "heel", "toe")
    _, report, _ = check_take_feet(take)
    assert report.up.label == "-Y"
    # The origin is the hip centre: the feet rest ~0.89 m below it (+Y is down).
    assert report.up.sign * report.floor.level == pytest.approx(0.89, abs=0.02)


def test_a_keypoint_take_without_legs_is_refused() -> None:
    names = ("Nose", "LEar", "REar")
    take = KeypointSequence(names, np.zeros((5, 3, 3)), np.ones((5, 3)), 30.0)
    with pytest.raises(InputError, match="Expected hip, knee and ankle keypoints on both sides"):
        check_take_feet(take)


def test_a_bvh_take_without_feet_is_refused() -> None:
    motion = parse_bvh(ARMLESS_LEGLESS)
    with pytest.raises(InputError, match="Expected a rig with upper leg, lower leg and foot"):
        check_take_feet(motion)
