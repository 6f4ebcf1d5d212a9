"""Limits models on real takes: build, save/load, shipped defaults, refusals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.errors import LimitsFileError
from mocapqa.io.bvh import read_bvh
from mocapqa.limits.analysis import check_limits, joint_map_json
from mocapqa.limits.build import BuildParams, build_model
from mocapqa.limits.discriminator import DiscriminatorParams
from mocapqa.limits.model import LimitsModel
from mocapqa.limits.occupancy import OccupancyParams, evaluate
from mocapqa.limits.storage import (
    default_model_paths,
    load_default_model,
    load_model,
    model_bytes,
    save_model,
)

BANDAI = ("dataset-1_walk_normal_001.bvh", "dataset-2_walk_normal_001.bvh")
TINY = BuildParams(
    occupancy=OccupancyParams(bin_deg=15.0, dilation_bins=1, tau_margin_deg=20.0, interpolate=True),
    discriminator=DiscriminatorParams(n_valid=300, hidden_sizes=(8,), max_iter=150),
)


@pytest.fixture(scope="module")
def bandai_model(corpus_dir: Path) -> LimitsModel:
    motions = [read_bvh(corpus_dir / "bvh" / "bandai" / name) for name in BANDAI]
    return build_model(motions, list(BANDAI), TINY)


def test_a_model_keeps_every_limb_joint_with_its_bone_axis(bandai_model: LimitsModel) -> None:
    assert bandai_model.rig_family == "bandai"
    assert len(bandai_model.joints) == 14
    # Bandai bones run along +X on the left side and −X on the right (data README).
    np.testing.assert_allclose(bandai_model.joint("UpperArm_L").axis, [1.0, 0.0, 0.0], atol=1e-3)
    np.testing.assert_allclose(bandai_model.joint("UpperArm_R").axis, [-1.0, 0.0, 0.0], atol=1e-3)
    assert bandai_model.fingerprint["right_forearm"] == ("LowerArm_R", "-x")


def test_the_build_takes_pass_their_own_model(bandai_model: LimitsModel, corpus_dir: Path) -> None:
    motion = read_bvh(corpus_dir / "bvh" / "bandai" / BANDAI[0])
    report = check_limits(motion, bandai_model)
    assert report.valid.shape == (motion.n_frames, 14)
    assert report.flagged_fraction == 0.0
    assert np.all(report.score_deg == 0.0)


def test_a_twisted_forearm_is_flagged_and_scored(
    bandai_model: LimitsModel, corpus_dir: Path
) -> None:
    from dataclasses import replace

    from mocapqa.kinematics.quaternion import multiply, quats_from_axis_angle

    motion = read_bvh(corpus_dir / "bvh" / "bandai" / BANDAI[0])
    j = motion.skeleton.index("LowerArm_L")
    quats = motion.quats.copy()
    quats[:, j] = multiply(
        quats[:, j], quats_from_axis_angle(np.array([1.0, 0.0, 0.0]), np.pi * 0.9)
    )
    report = check_limits(replace(motion, quats=quats), bandai_model)
    column = report.joint_names.index("LowerArm_L")
    assert report.valid[:, column].mean() < 0.1
    assert np.median(report.score_deg[~report.valid[:, column], column]) > 10.0
    data = report.to_json(max_points=50)
    assert data["flagged_fraction"] == pytest.approx(report.flagged_fraction)
    joint = data["joints"][column]
    assert joint["worst_frames"]
    assert len(joint["frames"]["frame"]) <= 50


def test_a_model_survives_a_save_and_load(bandai_model: LimitsModel, tmp_path: Path) -> None:
    path = tmp_path / "bandai.npz"
    save_model(bandai_model, path)
    loaded = load_model(path)
    assert loaded.fingerprint == bandai_model.fingerprint
    assert loaded.corpus_hash == bandai_model.corpus_hash
    # The loaded maps check exactly as the built ones: the interpolated twist surface too
    # (a loader that dropped the flag read every shipped map as steps at the bin edges).
    rng = np.random.default_rng(0)
    params = rng.uniform(-np.pi, np.pi, (2000, 3))
    for a, b in zip(loaded.joints, bandai_model.joints, strict=True):
        np.testing.assert_array_equal(a.occupancy.occupied, b.occupancy.occupied)
        np.testing.assert_allclose(a.occupancy.tau_max, b.occupancy.tau_max, rtol=1e-6)
        assert a.occupancy.interpolate == b.occupancy.interpolate
        assert b.occupancy.interpolate == bandai_model.occupancy_params.interpolate
        np.testing.assert_allclose(
            evaluate(a.occupancy, params)[2], evaluate(b.occupancy, params)[2], atol=1e-4
        )
        assert a.network is not None
        assert b.network is not None
        np.testing.assert_array_equal(a.network.hidden_weights, b.network.hidden_weights)
    assert joint_map_json(loaded, "left_forearm")["name"] == "LowerArm_L"


def test_a_corrupted_model_file_is_refused(bandai_model: LimitsModel, tmp_path: Path) -> None:
    data = bytearray(model_bytes(bandai_model))
    truncated = tmp_path / "truncated.npz"
    truncated.write_bytes(bytes(data[: len(data) // 2]))
    with pytest.raises(LimitsFileError, match="Expected a mocapqa limits model"):
        load_model(truncated)
    garbage = tmp_path / "garbage.npz"
    garbage.write_bytes(b"not a model at all")
    with pytest.raises(LimitsFileError, match="unreadable or corrupt"):
        load_model(garbage)
    pickled = tmp_path / "pickled.npz"
    np.savez(pickled, meta=np.array([{"format": "mocapqa-limits"}], dtype=object))
    with pytest.raises(LimitsFileError, match="Expected a mocapqa limits model"):
        load_model(pickled)


def test_a_model_refuses_a_take_of_another_rig(bandai_model: LimitsModel, cmu_walk: Path) -> None:
    with pytest.raises(LimitsFileError, match="Expected a skeleton of the 'bandai' rig"):
        check_limits(read_bvh(cmu_walk), bandai_model)


@pytest.mark.parametrize(
    ("relative", "family"),
    [
        ("bvh/bandai/dataset-2_raise-up-both-hands_normal_001.bvh", "canonical"),
        ("bvh/cmu/iclone/002_10.bvh", "character_creator"),
        ("bvh/cmu/cmu_12_01_walk.bvh", "canonical"),
        ("bvh/misc/AV_8Walk_Meredith_HVHA_Rep1.bvh", "canonical"),
    ],
)
def test_shipped_models_cover_real_takes_of_each_rig(
    corpus_dir: Path, relative: str, family: str
) -> None:
    motion = read_bvh(corpus_dir / relative)
    model = load_default_model(motion.skeleton)
    assert model.rig_family == family
    report = check_limits(motion)
    assert report.flagged_fraction < 0.05
    assert len(report.roles) == 14
    assert all(j.scores is not None and j.scores.accuracy >= 0.9 for j in model.joints)


@pytest.mark.parametrize("name", ["bvh_example.bvh", "bvh_test2.bvh", "bvh_test3.bvh"])
def test_every_humanoid_file_of_the_corpus_gets_a_check(corpus_dir: Path, name: str) -> None:
    # Z-up, other names, a foot bone along −Y: rigs no per-rig model covers.
    motion = read_bvh(corpus_dir / "bvh" / "misc" / name)
    assert load_default_model(motion.skeleton).frame == "canonical"
    report = check_limits(motion)
    assert len(report.roles) == 14
    assert report.not_checked  # the spine, head, fingers, ... are named, not passed silently


def test_shipped_models_are_small() -> None:
    paths = list(default_model_paths())
    assert [p.name for p in paths] == [
        "bandai.npz", "canonical.npz", "character_creator.npz", "cmu.npz",
    ]  # fmt: skip
    assert sum(p.stat().st_size for p in paths) <= 5 * 1024 * 1024


def test_every_shipped_network_meets_the_accuracy_target() -> None:
    # Issue target: >= 97 % held-out synthetic test accuracy on every joint of every rig, with
    # the test split of the synthetic set (15 % of 2 x n_valid samples): 20,000 valid samples
    # for every model (the canonical one since its rebuild with 64-unit networks tried,
    # docs/limits.md; before, 5,000 and a 96 % floor for its left upper arm's 96.27 %).
    def split(n_valid: int) -> int:
        return 2 * n_valid - int(0.70 * 2 * n_valid) - int(0.15 * 2 * n_valid)

    for path in default_model_paths():
        model = load_model(path)
        n_test = split(DiscriminatorParams().n_valid)
        for joint in model.joints:
            assert joint.scores is not None, f"{path.name}: {joint.name} has no network"
            assert joint.scores.n_test == n_test, f"{path.name}: {joint.name}"
            assert joint.scores.accuracy >= 0.97, f"{path.name}: {joint.name}"
