"""The pipeline on real takes: options, frame grid, points, and each step's output."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tests.rigs import rerig, roll_joint

from mocapqa.core.decimate import sample_frames
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.formats import read_take
from mocapqa.jobs.demo import demo_paths
from mocapqa.jobs.run_outputs import write_outputs
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.frames import motion_points, motion_pose, rigid_bones
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.pipeline.steps import true_runs, violation_findings
from mocapqa.store.files import FileStore


def test_options_round_trip_and_name_bad_fields() -> None:
    options = AnalysisOptions.from_json(
        {"checks": ["twist"], "filter_method": "kalman", "filter_params": {"gate_sigma": 3}}
    )
    assert AnalysisOptions.from_json(options.to_json()) == options
    assert AnalysisOptions.from_json(None) == AnalysisOptions()
    with pytest.raises(InputError, match="Expected option fields among"):
        AnalysisOptions.from_json({"speed": 1})
    with pytest.raises(InputError, match=r"^checks: Expected names among"):
        AnalysisOptions(checks=("twist", "colour"))
    with pytest.raises(InputError, match=r"^twist_method: Expected one of"):
        AnalysisOptions(twist_method="guess")
    with pytest.raises(InputError, match=r"^filter_method: Expected one of"):
        AnalysisOptions(filter_method="median")
    with pytest.raises(InputError, match=r"^max_points: Expected an integer"):
        AnalysisOptions.from_json({"max_points": "many"})


@pytest.mark.parametrize(("n_frames", "max_points"), [(5, 10), (10_000, 2000), (2001, 2000)])
def test_sample_frames_keeps_ends_and_the_limit(n_frames: int, max_points: int) -> None:
    frames = sample_frames(n_frames, max_points)
    assert frames[0] == 0
    assert frames[-1] == n_frames - 1
    assert len(frames) <= max_points
    assert np.all(np.diff(frames) > 0)


def test_motion_points_are_fk_joints_then_end_sites(cmu_walk: Path) -> None:
    motion = read_bvh(cmu_walk)
    names, parents, points = motion_points(motion)
    _, positions = forward_kinematics(motion)
    n_joints, n_sites = motion.skeleton.n_joints, len(motion.skeleton.end_sites)
    assert points.shape == (motion.n_frames, n_joints + n_sites, 3)
    np.testing.assert_array_equal(points[:, :n_joints], positions)
    assert names[n_joints] == f"{motion.skeleton.names[parents[n_joints]]} end"


def test_motion_pose_gives_end_sites_their_parents_rotation(cmu_walk: Path) -> None:
    motion = read_bvh(cmu_walk)
    _, parents, points, rotations = motion_pose(motion)
    quats, _ = forward_kinematics(motion)
    n_joints = motion.skeleton.n_joints
    assert rotations.shape == (*points.shape[:2], 4)
    np.testing.assert_array_equal(rotations[:, :n_joints], quats)
    np.testing.assert_array_equal(rotations[:, n_joints:], quats[:, parents[n_joints:]])


def test_violation_findings_cover_each_run_of_bad_frames() -> None:
    valid = np.ones((10, 2), dtype=bool)
    valid[2:5, 0] = False
    valid[9, 1] = False
    score = np.zeros((10, 2))
    score[3, 0] = 12.5
    score[9, 1] = 4.0
    findings = violation_findings(valid, score, ["elbow", "knee"])
    assert [(f["joint"], f["start_frame"], f["end_frame"], f["value"]) for f in findings] == [
        ("elbow", 2, 4, 12.5),
        ("knee", 9, 9, 4.0),
    ]


def test_analyze_motion_reports_steps_and_progress() -> None:
    motion = read_bvh(demo_paths()[0])
    calls: list[tuple[int, str]] = []
    result = analyze(motion, AnalysisOptions(max_points=200), lambda p, s: calls.append((p, s)))
    percents = [p for p, _ in calls]
    assert percents == sorted(percents)
    assert percents[0] > 0
    assert percents[-1] <= 100
    report = result.report
    assert report["kind"] == "motion"
    assert report["steps"]["twist"]["state"] == "done"
    limits = report["steps"]["limits"]
    if limits["state"] == "done":
        heat = np.asarray(report["series"]["limits"]["score_deg"])
        n_samples = len(report["series"]["frames"])
        assert heat.shape == (len(report["series"]["limits"]["joints"]), n_samples)
        assert np.all(heat >= 0)
        # The heat map's hover text: a read-out exactly where a cell is flagged.
        readout = np.asarray(report["series"]["limits"]["readout"])
        assert readout.shape == heat.shape
        np.testing.assert_array_equal(readout != "", heat > 0)
    else:
        assert limits["state"] == "no_model"
        assert "no model for this rig" in limits["message"]
    frames = report["series"]["frames"]
    assert 100 < len(frames) <= 200 < motion.n_frames
    assert report["series"]["twist"]["frames"] == frames
    # Every finding's first frame is on the plotted axis.
    assert {f["start_frame"] for f in report["findings"]} <= set(frames)
    assert result.corrected_motion is not None
    assert result.raw_points.shape == result.corrected_points.shape
    twist_joints = {f["joint"] for f in report["findings"] if f["kind"] == "twist"}
    assert twist_joints == {"LeftArm", "LeftLeg"}  # the demo README's injected joints


def test_analyze_keypoints_filters_and_keeps_the_input(corpus_dir: Path) -> None:
    path = corpus_dir / (
        "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
    )
    sequence = read_take(path)
    before = np.array(sequence.positions, copy=True)
    result = analyze(sequence, AnalysisOptions())
    np.testing.assert_array_equal(sequence.positions, before)
    assert result.filtered_keypoints is not None
    assert result.corrected_motion is None
    assert result.report["steps"]["filter"]["state"] == "done"
    assert not np.allclose(result.filtered_keypoints.positions, sequence.positions, equal_nan=True)


def test_undetected_openpose_keypoints_stay_missing_in_the_stored_points(
    corpus_dir: Path, tmp_path: Path
) -> None:
    folder = corpus_dir / "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-associated"
    take = read_take(folder / "cam01_json")
    assert isinstance(take, KeypointSequence)
    undetected = np.isnan(take.positions).any(axis=-1)
    assert undetected.sum() == 90  # the corpus README: 90 zeroed keypoints in cam01
    result = analyze(take, AnalysisOptions())
    files = FileStore(tmp_path)
    write_outputs(files, "0123456789abcdef0123456789abcdef", result)
    with np.load(files.run_dir("0123456789abcdef0123456789abcdef") / "points.npz") as data:
        raw = data["raw"]
    np.testing.assert_array_equal(np.isnan(raw).any(axis=-1), undetected)
    assert not np.any(np.all(raw[~undetected] == 0, axis=-1))


def test_keypoint_confidence_and_bridged_samples_are_stored_for_the_view(
    corpus_dir: Path, tmp_path: Path
) -> None:
    folder = corpus_dir / "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-associated"
    take = read_take(folder / "cam01_json")
    assert isinstance(take, KeypointSequence)
    undetected = np.isnan(take.positions).any(axis=-1)
    result = analyze(take, AnalysisOptions())
    files = FileStore(tmp_path)
    write_outputs(files, "0123456789abcdef0123456789abcdef", result)
    with np.load(files.run_dir("0123456789abcdef0123456789abcdef") / "points.npz") as data:
        confidence, bridged = data["confidence"], data["bridged"]
    np.testing.assert_allclose(confidence, take.confidence, atol=1e-3)
    assert np.all(confidence[undetected] == 0)
    # The filter bridges every undetected sample; the report's runs are the frames with one.
    assert bridged[undetected].all()
    runs = result.report["series"]["filter"]["bridged_runs"]
    marked = np.zeros(take.n_frames, dtype=bool)
    for first, last in runs:
        marked[first : last + 1] = True
    np.testing.assert_array_equal(marked, bridged.any(axis=1))
    assert runs


def test_true_runs_are_first_and_last_of_each_run() -> None:
    flags = np.array([True, True, False, True, False, False, True])
    assert true_runs(flags).tolist() == [[0, 1], [3, 3], [6, 6]]
    assert true_runs(np.zeros(4, dtype=bool)).shape == (0, 2)


def test_a_travelling_joint_is_not_joined_to_its_parent_by_a_bone(corpus_dir: Path) -> None:
    """Bandai's Hips carries the take's travel under a joint_Root that stays at the origin:
    the 3D view draws no bone between them, and every other bone of every rig."""
    bandai = read_bvh(corpus_dir / "bvh" / "bandai" / "dataset-2_walk_normal_001.bvh")
    bones = rigid_bones(bandai)
    skeleton = bandai.skeleton
    hips, root = skeleton.index("Hips"), skeleton.index("joint_Root")
    assert [root, hips] not in bones
    assert len(bones) == skeleton.n_joints - 2 + len(skeleton.end_sites)
    walk = read_bvh(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    assert len(rigid_bones(walk)) == walk.skeleton.n_joints - 1 + len(walk.skeleton.end_sites)
    result = analyze(bandai, AnalysisOptions(checks=("twist",)))
    assert result.report["points"]["bones"] == bones


def test_the_limits_step_frames_an_unseen_rig_without_the_twist_intervals(
    corpus_dir: Path,
) -> None:
    """A short take of a rig no model has seen (the CMU walk with turned joint frames), its
    left thigh rolled 90° on 50 of 60 frames with the children undoing it: framed from
    itself, the roll set the thigh's frame and read as nothing; the pipeline hands the twist
    step's intervals to the limits step, which frames the thigh from the clean frames and
    flags the rolled ones."""
    walk = read_bvh(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    short = rerig(Motion(walk.skeleton, walk.quats[1:61], walk.translations[1:61], walk.fps), 5)
    thigh = short.skeleton.index("LeftUpLeg")
    damaged = roll_joint(short, thigh, 90.0, slice(5, 55))

    def flagged(options: AnalysisOptions) -> float:
        report = analyze(damaged, options).report
        assert report["steps"]["limits"]["state"] == "done"
        messages.append(report["steps"]["limits"]["message"])
        frames = np.zeros(damaged.n_frames, dtype=bool)
        for f in report["findings"]:
            if f["kind"] == "limits" and f["joint"] == "LeftUpLeg":
                frames[f["start_frame"] : f["end_frame"] + 1] = True
        return float(frames[5:55].mean())

    messages = []

    with_twist = flagged(AnalysisOptions(checks=("twist", "limits")))
    alone = flagged(AnalysisOptions(checks=("limits",)))
    assert with_twist >= 0.85  # 45 of the 50 rolled frames
    assert alone == 0.0
    # The step says how it read the take.
    assert "estimated from this take, " in messages[0]
    assert "inside twist intervals left out" in messages[0]
    assert "estimated from this take)" in messages[1]
