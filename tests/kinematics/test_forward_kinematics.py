"""Forward kinematics on real takes against two independent references.

* pybvh 0.9's ``node_positions`` (joints and End Sites) on the CMU walk;
* a per-joint FK written here with scipy's Rotation from the channel values, on a Bandai take
  and on a pybvh sample with position channels on non-root joints.
Tolerance: 1e-6 of the skeleton's size (the extent of its first frame).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocapqa.core.motion import POSITION_CHANNELS, Motion
from mocapqa.errors import ShapeError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import channel_values
from mocapqa.kinematics.forward import end_site_positions, forward_kinematics, world_from_local
from mocapqa.kinematics.quaternion import multiply, rotate


def skeleton_size(positions: np.ndarray) -> float:
    return float(np.max(np.ptp(positions[0], axis=0)))


def scipy_forward_kinematics(motion: Motion) -> np.ndarray:
    """World joint positions (F, J, 3) from the channel values, one joint at a time."""
    sk = motion.skeleton
    values = channel_values(motion)
    n_frames = motion.n_frames
    world_rot: list[Rotation] = []
    world_pos = np.zeros((n_frames, sk.n_joints, 3))
    column = 0
    for j in range(sk.n_joints):
        chans = sk.channels[j]
        block = values[:, column : column + len(chans)]
        column += len(chans)
        translation = np.tile(sk.offsets[j], (n_frames, 1))
        order = ""
        angles = []
        for k, channel in enumerate(chans):
            if channel in POSITION_CHANNELS:
                translation[:, "XYZ".index(channel[0])] = block[:, k]
            else:
                order += channel[0]
                angles.append(block[:, k])
        local = (
            Rotation.from_euler(order, np.stack(angles, axis=1), degrees=True)
            if order
            else Rotation.identity(n_frames)
        )
        parent = int(sk.parents[j])
        if parent < 0:
            world_rot.append(local)
            world_pos[:, j] = translation
        else:
            world_rot.append(world_rot[parent] * local)
            world_pos[:, j] = world_pos[:, parent] + world_rot[parent].apply(translation)
    return world_pos


def test_cmu_walk_matches_pybvh_node_positions(cmu_walk: Path) -> None:
    import pybvh  # the `bench` extra, also in `dev`

    theirs_take = pybvh.read_bvh_file(str(cmu_walk))
    theirs = theirs_take.node_positions()
    index = theirs_take.node_index
    motion = read_bvh(cmu_walk)
    world_quats, positions = forward_kinematics(motion)
    sites = end_site_positions(motion, world_quats, positions)
    sk = motion.skeleton
    tolerance = 1e-6 * skeleton_size(positions)
    assert tolerance > 1e-6  # the CMU skeleton is ~24 units tall
    for j, name in enumerate(sk.names):
        np.testing.assert_allclose(positions[:, j], theirs[:, index[name]], rtol=0, atol=tolerance)
    for e, site in enumerate(sk.end_sites):
        name = f"EndSite{sk.names[site.parent]}"
        np.testing.assert_allclose(sites[:, e], theirs[:, index[name]], rtol=0, atol=tolerance)


@pytest.mark.parametrize("relative", ["bandai/dataset-1_walk_normal_001.bvh", "misc/bvh_test3.bvh"])
def test_positions_match_a_scipy_built_forward_kinematics(corpus_dir: Path, relative: str) -> None:
    motion = read_bvh(corpus_dir / "bvh" / relative)
    assert motion.skeleton.root_translation == "replace"
    _, positions = forward_kinematics(motion)
    expected = scipy_forward_kinematics(motion)
    tolerance = 1e-6 * skeleton_size(expected)
    np.testing.assert_allclose(positions, expected, rtol=0, atol=tolerance)


def test_world_from_local_composes_a_two_joint_chain() -> None:
    parents = np.array([-1, 0])
    quarter_turn_z = Rotation.from_euler("z", 90, degrees=True).as_quat()
    local_quats = np.array([[quarter_turn_z, [0.0, 0.0, 0.0, 1.0]]])
    local_translations = np.array([[[1.0, 2.0, 3.0], [1.0, 0.0, 0.0]]])
    world_quats, world_positions = world_from_local(parents, local_quats, local_translations)
    # The child sits one unit along the parent's rotated x axis, i.e. along +y.
    np.testing.assert_allclose(world_positions[0, 1], [1.0, 3.0, 3.0], atol=1e-15)
    np.testing.assert_allclose(world_quats[0, 1], quarter_turn_z, atol=1e-15)


def test_world_from_local_leaves_its_inputs_alone() -> None:
    # One frame, where a transposed array can be a view of the caller's.
    parents = np.array([-1, 0, 1])
    rng = np.random.default_rng(0)
    quats = Rotation.random(3, random_state=1).as_quat()[None]
    translations = rng.normal(size=(1, 3, 3))
    before = quats.copy(), translations.copy()
    world_from_local(parents, quats, translations)
    np.testing.assert_array_equal(quats, before[0])
    np.testing.assert_array_equal(translations, before[1])


@pytest.mark.parametrize("relative", ["cmu/iclone/002_10.bvh", "misc/bvh_test3.bvh"])
def test_forward_kinematics_equals_world_from_local(corpus_dir: Path, relative: str) -> None:
    # Character Creator roots add their channels to the OFFSET; bvh_test3 has position
    # channels on non-root joints. forward_kinematics builds the local translations itself.
    motion = read_bvh(corpus_dir / "bvh" / relative)
    ours = forward_kinematics(motion)
    reference = world_from_local(motion.skeleton.parents, motion.quats, motion.local_translations())
    np.testing.assert_array_equal(ours[0], reference[0])
    np.testing.assert_array_equal(ours[1], reference[1])


def joint_by_joint(motion: Motion) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World rotations, positions and End Site positions with the NumPy quaternion helpers."""
    sk = motion.skeleton
    local = motion.local_translations()
    quats = np.empty_like(motion.quats)
    positions = np.empty_like(local)
    for j, parent in enumerate(sk.parents):
        if parent < 0:
            quats[:, j], positions[:, j] = motion.quats[:, j], local[:, j]
        else:
            quats[:, j] = multiply(quats[:, parent], motion.quats[:, j])
            positions[:, j] = positions[:, parent] + rotate(quats[:, parent], local[:, j])
    sites = np.stack(
        [positions[:, e.parent] + rotate(quats[:, e.parent], np.array(e.offset))
         for e in sk.end_sites],
        axis=1,
    )  # fmt: skip
    return quats, positions, sites


@pytest.mark.parametrize(
    "relative", ["cmu/cmu_12_01_walk.bvh", "cmu/iclone/002_10.bvh", "misc/bvh_test3.bvh"]
)
def test_the_compiled_loops_give_the_quaternion_helpers_results_bit_for_bit(
    corpus_dir: Path, relative: str
) -> None:
    motion = read_bvh(corpus_dir / "bvh" / relative)
    world_quats, positions = forward_kinematics(motion)
    sites = end_site_positions(motion, world_quats, positions)
    expected = joint_by_joint(motion)
    np.testing.assert_array_equal(world_quats, expected[0])
    np.testing.assert_array_equal(positions, expected[1])
    np.testing.assert_array_equal(sites, expected[2])


@pytest.mark.parametrize(
    ("parents", "quats_shape", "translations_shape", "message"),
    [
        ([-1, 2, 0], (2, 3, 4), (2, 3, 3), "precede its child"),
        ([-1, 0, 3], (2, 3, 4), (2, 3, 3), "precede its child"),
        ([-2, 0, 1], (2, 3, 4), (2, 3, 3), "precede its child"),
        ([[-1, 0, 1]], (2, 3, 4), (2, 3, 3), "parents of shape"),
        ([-1, 0], (2, 3, 4), (2, 3, 3), "local_quats of shape"),
        ([-1, 0, 1], (2, 3, 3), (2, 3, 3), "local_quats of shape"),
        ([-1, 0, 1], (2, 3, 4), (3, 3, 3), "local_translations of shape"),
    ],
)
def test_world_from_local_refuses_what_the_compiled_loop_cannot_take(
    parents: list[int], quats_shape: tuple[int, ...], translations_shape: tuple[int, ...],
    message: str,
) -> None:  # fmt: skip
    quats = np.zeros(quats_shape)
    quats[..., -1] = 1.0
    with pytest.raises(ShapeError, match=message):
        world_from_local(np.array(parents), quats, np.zeros(translations_shape))


def test_end_site_positions_refuses_world_arrays_of_another_take(cmu_walk: Path) -> None:
    motion = read_bvh(cmu_walk)
    world_quats, positions = forward_kinematics(motion)
    with pytest.raises(ShapeError, match="Expected world rotations and positions"):
        end_site_positions(motion, world_quats[:-1], positions[:-1])


def test_a_take_without_frames_has_empty_world_arrays(cmu_walk: Path) -> None:
    motion = read_bvh(cmu_walk)
    empty = Motion(motion.skeleton, motion.quats[:0], motion.translations[:0], motion.fps)
    world_quats, positions = forward_kinematics(empty)
    assert world_quats.shape == (0, 31, 4)
    assert positions.shape == (0, 31, 3)
    assert end_site_positions(empty, world_quats, positions).shape == (0, 7, 3)
