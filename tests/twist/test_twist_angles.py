"""Twist angles and chain geometry, checked against scipy's Rotation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.twist.angles import (
    chain_geometry,
    child_azimuth_increments,
    child_increment_twists,
    parent_increment_twists,
    parent_twist_angles,
    wrap_angle,
)


def _perpendicular(axis: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    v: np.ndarray = np.cross(axis, rng.normal(size=3))
    return v / float(np.linalg.norm(v))


def test_parent_twist_angle_recovers_the_twist_of_swing_times_twist() -> None:
    rng = np.random.default_rng(3)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    theta = rng.uniform(-3.0, 3.0, size=50)
    swing_angles = rng.uniform(-2.5, 2.5, size=50)
    swing_axes = np.stack([_perpendicular(axis, rng) for _ in range(50)])
    quats = (
        Rotation.from_rotvec(swing_axes * swing_angles[:, None])
        * Rotation.from_rotvec(axis[None] * theta[:, None])
    ).as_quat()
    got = parent_twist_angles(quats[:, None], axis[None])[:, 0]
    np.testing.assert_allclose(got, theta, atol=1e-9)


def test_increments_equal_the_change_of_a_twist_about_the_bone() -> None:
    rng = np.random.default_rng(4)
    axis = np.array([0.0, 1.0, 0.0])
    base = Rotation.from_rotvec(rng.normal(size=3))
    theta = np.cumsum(rng.uniform(-0.3, 0.3, size=40))
    parent = (base * Rotation.from_rotvec(axis[None] * theta[:, None])).as_quat()
    # Random hemisphere signs must not matter.
    parent *= rng.choice((-1.0, 1.0), size=(40, 1))
    got = parent_increment_twists(parent[:, None], axis[None])[:, 0]
    np.testing.assert_allclose(got[1:], np.diff(theta), atol=1e-9)
    child = (Rotation.from_rotvec(axis[None] * -theta[:, None]) * base).as_quat()
    got_child = child_increment_twists(child[:, None], axis[None])[:, 0]
    np.testing.assert_allclose(got_child[1:], -np.diff(theta), atol=1e-9)


def test_azimuth_increment_follows_a_vector_turning_about_the_axis() -> None:
    axis = np.array([1.0, 0.0, 0.0])
    angles = np.linspace(0.0, 1.5, 16)
    quats = Rotation.from_rotvec(axis[None] * angles[:, None]).as_quat()
    increments, conditioning = child_azimuth_increments(
        quats[:, None], axis[None], np.array([[0.0, 1.0, 0.0]])
    )
    np.testing.assert_allclose(increments[1:, 0], np.diff(angles), atol=1e-12)
    np.testing.assert_allclose(conditioning, 1.0)


def test_wrap_angle_maps_into_half_open_interval() -> None:
    wrapped = wrap_angle(np.array([np.pi, -np.pi, 3 * np.pi, 0.5, -7.0]))
    np.testing.assert_allclose(wrapped, [np.pi, np.pi, np.pi, 0.5, -7.0 + 2 * np.pi])


@pytest.mark.parametrize("rig", ["cmu", "iclone", "bandai"])
def test_every_rig_has_ten_chains_with_axes_along_the_child_offset(
    takes: dict[str, Motion], rig: str
) -> None:
    skeleton = takes[rig].skeleton
    chains = limb_chains(find_roles(skeleton))
    assert len(chains) == 10
    for chain in chains:
        geometry = chain_geometry(skeleton, chain)
        offset = skeleton.offsets[chain.child]
        np.testing.assert_allclose(geometry.axis, offset / np.linalg.norm(offset), atol=1e-12)
        assert geometry.intermediates == ()
