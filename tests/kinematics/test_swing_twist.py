"""Swing–twist invariants (hypothesis), with scipy's Rotation as the reference."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from kinematics_strategies import axes, unit_quats
from scipy.spatial.transform import Rotation

from mocapqa.kinematics.quaternion import multiply
from mocapqa.kinematics.swing_twist import swing_twist, twist_angle, twist_swing

ATOL = 1e-12


def assert_same_rotation(p: np.ndarray, q: np.ndarray, atol: float = ATOL) -> None:
    """Equal up to the quaternion sign."""
    gap = min(np.max(np.abs(p - q)), np.max(np.abs(p + q)))
    assert gap <= atol, f"{p} and {q} differ by {gap}"


@settings(deadline=None, max_examples=100)
@given(q=unit_quats(), axis=axes())
def test_swing_then_twist_composes_to_the_input(q: np.ndarray, axis: np.ndarray) -> None:
    swing, twist = swing_twist(q, axis)
    assert_same_rotation(multiply(swing, twist), q)
    np.testing.assert_allclose(np.linalg.norm(swing), 1.0, atol=ATOL)
    np.testing.assert_allclose(np.linalg.norm(twist), 1.0, atol=ATOL)
    # The twist turns about the axis; the swing about an axis perpendicular to it.
    np.testing.assert_allclose(np.cross(twist[:3], axis), 0.0, atol=ATOL)
    np.testing.assert_allclose(np.dot(swing[:3], axis), 0.0, atol=ATOL)


@settings(deadline=None, max_examples=100)
@given(q=unit_quats(), axis=axes())
def test_twist_then_swing_composes_to_the_input(q: np.ndarray, axis: np.ndarray) -> None:
    twist, swing = twist_swing(q, axis)
    assert_same_rotation(multiply(twist, swing), q)
    np.testing.assert_allclose(np.cross(twist[:3], axis), 0.0, atol=ATOL)
    np.testing.assert_allclose(np.dot(swing[:3], axis), 0.0, atol=ATOL)


@settings(deadline=None, max_examples=100)
@given(q=unit_quats(), axis=axes())
def test_twist_angle_is_the_angle_of_the_twist(q: np.ndarray, axis: np.ndarray) -> None:
    _, twist = swing_twist(q, axis)
    angle = float(twist_angle(q, axis))
    assert -np.pi <= angle <= np.pi
    expected = Rotation.from_rotvec(angle * axis).as_quat()
    assert_same_rotation(twist, expected, atol=1e-9)


def test_pure_twist_and_pure_swing_split_cleanly() -> None:
    axis = np.array([0.0, 1.0, 0.0])
    twist_only = Rotation.from_rotvec([0.0, 0.7, 0.0]).as_quat()
    swing, twist = swing_twist(twist_only, axis)
    assert_same_rotation(twist, twist_only)
    assert_same_rotation(swing, np.array([0.0, 0.0, 0.0, 1.0]))
    swing_only = Rotation.from_rotvec([0.4, 0.0, -0.2]).as_quat()
    swing, twist = swing_twist(swing_only, axis)
    assert_same_rotation(swing, swing_only)
    assert_same_rotation(twist, np.array([0.0, 0.0, 0.0, 1.0]))


def test_half_turn_swing_gives_the_identity_twist() -> None:
    # Documented convention: the twist of a 180° swing is undefined; we return identity.
    half_turn = Rotation.from_rotvec([np.pi, 0.0, 0.0]).as_quat()
    swing, twist = swing_twist(half_turn, np.array([0.0, 1.0, 0.0]))
    assert_same_rotation(twist, np.array([0.0, 0.0, 0.0, 1.0]))
    assert_same_rotation(swing, half_turn)
    assert twist_angle(half_turn, np.array([0.0, 1.0, 0.0])) == 0.0


def test_batches_decompose_per_element() -> None:
    rng = np.random.default_rng(7)
    quats = Rotation.random(60, random_state=rng).as_quat().reshape(20, 3, 4)
    axis = np.array([0.0, 0.0, 1.0])
    swing, twist = swing_twist(quats, axis)
    for index in np.ndindex(20, 3):
        one_swing, one_twist = swing_twist(quats[index], axis)
        np.testing.assert_array_equal(swing[index], one_swing)
        np.testing.assert_array_equal(twist[index], one_twist)
