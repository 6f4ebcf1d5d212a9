"""Canonical (anatomical) frames: rig-independent limits on real takes, re-rigged copies."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from tests.rigs import RENAMES, rerig, roll_joint

from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import geodesic_angle, multiply, rotate
from mocapqa.limits.analysis import LimitsReport, check_limits
from mocapqa.limits.build import BuildParams, build_canonical_model, with_rig_frames
from mocapqa.limits.canonical import CANONICAL_AXIS, frame_needs, rig_frames, rig_key
from mocapqa.limits.charting import canonical_quats
from mocapqa.limits.expmap import expmap_from_quats
from mocapqa.limits.model import LimitsModel
from mocapqa.limits.occupancy import OccupancyParams
from mocapqa.limits.storage import default_model_paths, load_model, model_bytes
from mocapqa.twist.analysis import analyze_twist

MAP_ONLY = BuildParams(
    occupancy=OccupancyParams(bin_deg=15.0, dilation_bins=2, tau_margin_deg=40.0, interpolate=True),
    discriminator=None,
)


@pytest.fixture(scope="module")
def cmu(corpus_dir: Path) -> Motion:
    motion = read_bvh(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    # Frame 0 is a synthetic T-pose that is not part of the walk.
    return Motion(motion.skeleton, motion.quats[1:], motion.translations[1:], motion.fps)


@pytest.fixture(scope="module")
def bandai_model(corpus_dir: Path) -> LimitsModel:
    names = ["dataset-1_walk_normal_001.bvh", "dataset-2_walk_normal_001.bvh"]
    motions = [read_bvh(corpus_dir / "bvh" / "bandai" / n) for n in names]
    return build_canonical_model(motions, names, MAP_ONLY)


def test_a_rerigged_renamed_take_has_the_same_world_poses(cmu: Motion) -> None:
    turned = rerig(cmu, seed=3, renames=RENAMES)
    _, before = forward_kinematics(cmu)
    _, after = forward_kinematics(turned)
    np.testing.assert_allclose(after, before, atol=1e-6)
    assert rig_key(turned) != rig_key(cmu)


def test_canonical_rotations_do_not_depend_on_the_joint_frames(cmu: Motion) -> None:
    frames, original = canonical_quats(cmu)
    turned_frames, turned = canonical_quats(rerig(cmu, seed=3, renames=RENAMES))
    assert turned_frames.roles == frames.roles
    assert len(frames.roles) == 14
    np.testing.assert_array_less(np.rad2deg(geodesic_angle(turned, original)), 1e-4)


def test_a_rerigged_take_gets_identical_limits_results(
    cmu: Motion, bandai_model: LimitsModel
) -> None:
    original = check_limits(cmu, bandai_model)
    turned = check_limits(rerig(cmu, seed=11, renames=RENAMES), bandai_model)
    assert turned.roles == original.roles
    np.testing.assert_array_equal(turned.valid, original.valid)
    np.testing.assert_allclose(turned.score_deg, original.score_deg, atol=1e-6)
    np.testing.assert_allclose(turned.params_deg, original.params_deg, atol=1e-6)


def test_the_same_anatomy_reads_alike_on_three_rigs(corpus_dir: Path) -> None:
    # Walks of three rigs (no walk of the corpus exists on two rigs): the knee and the elbow
    # flex the same way round, and the hinge joints hardly twist, on every rig.
    for relative in (
        "bvh/cmu/cmu_12_01_walk.bvh",
        "bvh/cmu/iclone/003_02.bvh",
        "bvh/bandai/dataset-1_walk_normal_001.bvh",
    ):
        motion = read_bvh(corpus_dir / relative)
        frames, quats = canonical_quats(motion)
        params = np.rad2deg(expmap_from_quats(quats, CANONICAL_AXIS))
        for side in ("left", "right"):
            knee = params[:, frames.roles.index(f"{side}_lower_leg")]
            elbow = params[:, frames.roles.index(f"{side}_forearm")]
            assert np.percentile(knee[:, 0], 90) > 40, relative  # flexion is +s1
            assert np.percentile(elbow[:, 0], 50) < -5, relative  # flexion is −s1
            assert np.percentile(np.abs(knee[:, 2]), 90) < 5, relative


def test_rig_frames_pool_takes_and_a_model_stores_them(
    corpus_dir: Path, bandai_model: LimitsModel
) -> None:
    names = ["dataset-1_walk_normal_001.bvh", "dataset-2_walk_normal_001.bvh"]
    motions = [read_bvh(corpus_dir / "bvh" / "bandai" / n) for n in names]
    pooled = rig_frames(motions)
    stored = bandai_model.rig_frames[rig_key(motions[0])]
    np.testing.assert_allclose(stored.frames, pooled.frames)
    assert stored.family == "bandai"
    again = load_model_from_bytes(model_bytes(bandai_model))
    assert again.frame == "canonical"
    np.testing.assert_allclose(again.rig_frames[rig_key(motions[0])].frames, pooled.frames)


def load_model_from_bytes(content: bytes) -> LimitsModel:
    import tempfile

    with tempfile.NamedTemporaryFile(suffix=".npz") as handle:
        handle.write(content)
        handle.flush()
        return load_model(handle.name)


def test_a_canonical_model_checks_an_unseen_rig_and_names_what_it_does_not_check(
    corpus_dir: Path, bandai_model: LimitsModel
) -> None:
    motion = read_bvh(corpus_dir / "bvh" / "cmu" / "iclone" / "003_02.bvh")
    report = check_limits(motion, bandai_model)
    assert report.joint_names[0] == "CC_Base_L_Clavicle"
    assert len(report.roles) == 14
    assert "CC_Base_Head" in report.not_checked
    assert "CC_Base_L_Thigh" not in report.not_checked
    data = report.to_json()
    assert data["not_checked"] == list(report.not_checked)
    flagged = [w for j in data["joints"] for w in j["worst_frames"]]
    assert all(w["readout"] for w in flagged)


def test_an_injected_knee_hyperextension_reads_as_such(
    cmu: Motion, bandai_model: LimitsModel
) -> None:
    # Bend the right knee 80° the wrong way (about its flexion axis) on frames 100–109.
    frames, _ = canonical_quats(cmu)
    k = frames.roles.index("right_lower_leg")
    joint = int(frames.joints[k])
    axis = rotate(frames.frames[k], np.array([1.0, 0.0, 0.0]))  # flexion axis, local frame
    half = np.deg2rad(-80.0) / 2
    turn = np.concatenate((np.sin(half) * axis, [np.cos(half)]))
    quats = cmu.quats.copy()
    quats[100:110, joint] = multiply(quats[100:110, joint], turn[None])
    bent = replace(cmu, quats=quats)
    report = check_limits(bent, bandai_model)
    column = report.roles.index("right_lower_leg")
    texts = [report.readout(f, column) for f in range(100, 110) if not report.valid[f, column]]
    assert texts, "the wrong-way knee was not flagged"
    assert all(t.startswith("right knee hyperextended") for t in texts), texts


def test_the_hands_axial_rotation_reads_alike_on_three_rigs(corpus_dir: Path) -> None:
    # The hand's frame follows the forearm's flexion axis: with the wrist's own bend plane the
    # median hand twist of the shipped model read 66° on Character Creator, −33° on CMU and
    # −42° on Bandai (the left hand), so every rig flooded the others' hand twist ranges.
    model = load_model(next(p for p in default_model_paths() if p.stem == "canonical"))
    for relative in (
        "bvh/cmu/cmu_12_01_walk.bvh",
        "bvh/cmu/iclone/003_02.bvh",
        "bvh/bandai/dataset-2_wave-both-hands_youthful_001.bvh",
    ):
        report = check_limits(read_bvh(corpus_dir / relative), model)
        for side in ("left", "right"):
            tau = report.params_deg[:, report.roles.index(f"{side}_hand"), 2]
            assert abs(np.median(tau)) < 20, (relative, side, np.median(tau))


def test_the_wrists_rest_near_neutral_on_three_rigs(corpus_dir: Path) -> None:
    # The hand's long axis continues the forearm on every rig. Pointed at the knuckles where a
    # rig has them (Character Creator), the shipped model read 002_03's right wrist 56° flexed
    # and 24° deviated, CMU's walk 7.5°, while Bandai and CMU hands, without knuckles, read 0.
    model = load_model(next(p for p in default_model_paths() if p.stem == "canonical"))
    for relative in (
        "bvh/cmu/cmu_12_01_walk.bvh",
        "bvh/cmu/iclone/002_03.bvh",
        "bvh/bandai/dataset-1_walk_normal_001.bvh",
    ):
        report = check_limits(read_bvh(corpus_dir / relative), model)
        for side in ("left", "right"):
            flexion = report.params_deg[:, report.roles.index(f"{side}_hand"), 0]
            assert abs(np.median(flexion)) < 5, (relative, side, np.median(flexion))


def test_a_hand_mapped_onto_a_bone_of_no_length_is_framed_from_its_forearm(cmu: Motion) -> None:
    # CMU's finger bases sit at the hand (zero OFFSET): mapped as the hands, their long axis
    # comes from the forearm joint, not from the zero bone to their parent.
    mapping = {"left_hand": "LeftFingerBase", "right_hand": "RightFingerBase"}
    frames = rig_frames([cmu], mapping)
    assert np.isfinite(frames.frames).all()
    # A forearm mapped onto its own hand has no long axis: a clear error, not a crash.
    with pytest.raises(InputError, match="bone of non-zero length"):
        rig_frames([cmu], {"left_forearm": "LeftHand", "left_hand": "LeftFingerBase"})
    # A leg role on an arm joint leaves no body frame: an error naming the mapping, where it
    # was an "internal error" of the run (scipy's non-positive determinant).
    with pytest.raises(InputError, match="check the role mapping"):
        rig_frames([cmu], {"left_upper_leg": "LeftArm"})


def test_an_unseen_rig_s_hands_are_not_flagged_by_a_model_of_the_other_rigs(
    corpus_dir: Path,
) -> None:
    # Leave one rig out on the hands: a map of Character Creator and CMU-style takes, the
    # Bandai hand-waving takes framed from themselves. With the wrist's bend plane as the
    # hand's flexion axis 9–13 % of their hand frames were flagged.
    root = corpus_dir / "bvh"
    walks = [root / "cmu" / "cmu_12_01_walk.bvh", root / "misc" / "AV_8Walk_Meredith_HVHA_Rep1.bvh"]
    others = [p for p in sorted((root / "cmu" / "iclone").glob("*.bvh")) if p.name != "005_05.bvh"]
    others += walks
    model = build_canonical_model([read_bvh(p) for p in others], [p.name for p in others], MAP_ONLY)
    for name in ("dataset-1_respond_normal_001.bvh", "dataset-2_wave-both-hands_youthful_001.bvh"):
        motion = read_bvh(root / "bandai" / name)
        assert rig_key(motion) not in model.rig_frames
        report = check_limits(motion, model)
        hands = [report.roles.index(f"{side}_hand") for side in ("left", "right")]
        assert (~report.valid[:, hands]).mean() < 0.01, name


def test_a_new_rig_framed_once_from_its_takes_keeps_its_frames_through_a_damaged_take(
    corpus_dir: Path, bandai_model: LimitsModel
) -> None:
    # A short take mostly corrupted by one twist offset on the left thigh: framed from itself,
    # its thigh frame follows the offset and the error reads as no twist at all; framed once
    # from the rig's clean takes, every corrupted frame is 90° off.
    root = corpus_dir / "bvh" / "cmu"
    names = ["cmu_12_01_walk.bvh"]
    walk = read_bvh(root / names[0])
    thigh = walk.skeleton.index("LeftUpLeg")
    short = Motion(walk.skeleton, walk.quats[1:61].copy(), walk.translations[1:61], walk.fps)
    damaged = roll_joint(short, thigh, 90.0, slice(5, 55))
    assert rig_key(damaged) not in bandai_model.rig_frames
    alone = check_limits(damaged, bandai_model)
    framed = with_rig_frames(bandai_model, [walk], names)
    assert rig_key(damaged) in framed.rig_frames
    once = check_limits(damaged, framed)
    truth = check_limits(short, framed)  # the undamaged take, framed once
    k = once.roles.index("left_upper_leg")

    def shift(report: LimitsReport) -> np.ndarray:
        offset = report.params_deg[5:55, k, 2] - truth.params_deg[5:55, k, 2]
        return np.abs((offset + 180.0) % 360.0 - 180.0)

    assert np.median(shift(alone)) < 30
    assert np.median(shift(once)) > 80
    assert (~once.valid[5:55, k]).mean() > (~alone.valid[5:55, k]).mean()
    # A per-rig model cannot take frames.
    with pytest.raises(InputError):
        with_rig_frames(replace(bandai_model, frame="rig"), [walk], names)


def test_a_take_framed_alone_leaves_out_its_twist_intervals(
    corpus_dir: Path, bandai_model: LimitsModel
) -> None:
    """The damaged take above, framed from itself as a take of an unseen rig is, but without
    the frames of the twist intervals the twist detector finds on it (as the pipeline and
    ``limits check`` do): the thigh frame comes from the clean frames, so the corrupted
    frames read 90° off, as when the rig is framed from clean takes."""
    walk = read_bvh(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    thigh = walk.skeleton.index("LeftUpLeg")
    short = Motion(walk.skeleton, walk.quats[1:61].copy(), walk.translations[1:61], walk.fps)
    damaged = roll_joint(short, thigh, 90.0, slice(5, 55))
    found = analyze_twist(damaged, apply="none").interval_frames()
    assert found[5:55, thigh].mean() > 0.9
    assert not found[:, thigh].all()
    left_out = check_limits(damaged, bandai_model, ignore=found)
    alone = check_limits(damaged, bandai_model)
    clean = check_limits(short, bandai_model)
    k = left_out.roles.index("left_upper_leg")

    def shift(report: LimitsReport) -> np.ndarray:
        offset = report.params_deg[5:55, k, 2] - clean.params_deg[5:55, k, 2]
        return np.abs((offset + 180.0) % 360.0 - 180.0)

    assert np.median(shift(alone)) < 30
    assert np.median(shift(left_out)) > 80
    # Nothing to leave out: the same frames as without the argument.
    nothing = np.zeros(short.quats.shape[:2], dtype=bool)
    np.testing.assert_array_equal(
        check_limits(short, bandai_model, ignore=nothing).params_deg, clean.params_deg
    )


def test_a_role_whose_frame_needs_a_missing_role_is_not_checked(cmu: Motion) -> None:
    # The forearms and lower legs renamed beyond any role table: a hand would be read against
    # the body frame instead of its forearm, an upper arm without its limb plane; both would
    # flag a clean walk. They are listed as not checked instead; the clavicles stay checked.
    renamed = rerig(cmu, seed=0, renames={"LeftForeArm": "SegA", "RightForeArm": "SegB",
                                          "LeftLeg": "SegC", "RightLeg": "SegD"})  # fmt: skip
    report = check_limits(renamed)
    assert report.roles == ("left_clavicle", "right_clavicle")
    for side in ("left", "right"):
        for role in ("upper_arm", "forearm", "hand", "upper_leg", "lower_leg", "foot"):
            assert f"{side}_{role}" in report.not_checked
    assert report.flagged_fraction == 0.0
    assert frame_needs("hand") == ("forearm",)
    assert frame_needs("upper_arm") == ("forearm",)  # a missing clavicle is stood in for
    assert frame_needs("forearm") == ("upper_arm",)
    assert frame_needs("upper_leg") == ("lower_leg",)


def test_an_upper_arm_without_a_clavicle_is_checked_against_the_mean_clavicle(
    cmu: Motion,
) -> None:
    """A rig without clavicles (Human3.6M-style) still gets its upper arms checked: the
    missing clavicle stands at the model's mean clavicle pose relative to the chest. On the
    CMU walk with its clavicles renamed beyond the role tables, the upper arms read within a
    few degrees of the full rig's reading and nothing is flagged."""
    renamed = rerig(cmu, seed=1, renames={"LeftShoulder": "SegA", "RightShoulder": "SegB"})
    report = check_limits(renamed)
    full = check_limits(cmu)
    assert "left_clavicle" in report.not_checked
    for side in ("left", "right"):
        role = f"{side}_upper_arm"
        assert role in report.roles
        mine, theirs = report.roles.index(role), full.roles.index(role)
        assert not (~report.valid[:, mine]).any()
        # The walk's clavicles hardly move, so the stand-in is close to the real one.
        gap = report.params_deg[:, mine] - full.params_deg[:, theirs]
        assert np.median(np.abs((gap + 180.0) % 360.0 - 180.0)) < 10.0
