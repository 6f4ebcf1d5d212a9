"""Euler angles ↔ quaternions in all six orders, against scipy's Rotation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from kinematics_strategies import angles_rad, unit_quats
from scipy.spatial.transform import Rotation

from mocapqa.errors import ShapeError
from mocapqa.kinematics.euler import EULER_ORDERS, euler_from_quats, quats_from_euler


def rotation_gap(p: np.ndarray, q: np.ndarray) -> float:
    """Largest component gap between quaternion arrays, up to sign per rotation."""
    same = np.max(np.abs(p - q), axis=-1)
    flipped = np.max(np.abs(p + q), axis=-1)
    return float(np.max(np.minimum(same, flipped)))


@pytest.mark.parametrize("order", EULER_ORDERS)
@settings(deadline=None, max_examples=60)
@given(angles=angles_rad())
def test_quats_from_euler_matches_scipy(order: str, angles: np.ndarray) -> None:
    expected = Rotation.from_euler(order, angles).as_quat()
    assert rotation_gap(quats_from_euler(angles, order), expected) < 1e-12


@pytest.mark.parametrize("order", EULER_ORDERS)
def test_quats_from_euler_far_outside_one_turn(order: str) -> None:
    """Unwrapped exports write angles of many turns; half-angle tangents pass every pole."""
    rng = np.random.default_rng(7)
    angles = np.concatenate(
        (
            rng.uniform(-1e4, 1e4, size=(500, 3)),
            # Exact multiples of a half and a whole turn, where tan(angle / 4) peaks.
            np.pi * rng.integers(-8, 9, size=(500, 3)),
        )
    )
    expected = Rotation.from_euler(order, angles).as_quat()
    assert rotation_gap(quats_from_euler(angles, order), expected) < 1e-12


@pytest.mark.parametrize("order", EULER_ORDERS)
def test_degrees_give_the_same_quaternions_as_converting_first(order: str) -> None:
    angles_deg = np.random.default_rng(3).uniform(-720.0, 720.0, size=(2000, 3))
    np.testing.assert_array_equal(
        quats_from_euler(angles_deg, order, degrees=True),
        quats_from_euler(np.deg2rad(angles_deg), order),
    )


@pytest.mark.filterwarnings("ignore:Gimbal lock detected:UserWarning")
@pytest.mark.parametrize("order", EULER_ORDERS)
@settings(deadline=None, max_examples=60)
@given(q=unit_quats())
def test_euler_round_trip_reproduces_the_rotation(order: str, q: np.ndarray) -> None:
    angles = euler_from_quats(q[None], order)[0]
    # Within 1e-7 rather than 1e-12: within ~1e-8 rad of gimbal lock scipy's as_euler (our
    # engine) resolves the coupled angles only to ~sqrt(machine epsilon); 1.4e-8 seen.
    assert rotation_gap(quats_from_euler(angles, order), q) < 1e-7
    # Same rotation as scipy's own angles (the triple itself may be an equivalent one).
    theirs = Rotation.from_quat(q).as_euler(order)
    assert rotation_gap(quats_from_euler(theirs, order), quats_from_euler(angles, order)) < 1e-7


@pytest.mark.parametrize("order", EULER_ORDERS)
def test_reference_angles_are_kept_when_they_describe_the_rotation(order: str) -> None:
    rng = np.random.default_rng(3)
    angles = rng.uniform(-3 * np.pi, 3 * np.pi, size=(200, 3))
    angles[:, 1] = rng.uniform(-1.4, 1.4, size=200)  # away from gimbal lock
    quats = quats_from_euler(angles, order)
    np.testing.assert_allclose(euler_from_quats(quats, order, angles), angles, atol=1e-9)


@pytest.mark.parametrize("order", EULER_ORDERS)
def test_smooth_rotation_paths_give_continuous_angles(order: str) -> None:
    rng = np.random.default_rng(EULER_ORDERS.index(order))
    t = np.linspace(0.0, 1.0, 600)[:, None]
    for _ in range(4):
        # A smooth path with a few turns; some cross gimbal lock of this order.
        rotvecs = t * rng.normal(0, 5, 3) + t**2 * rng.normal(0, 5, 3)
        quats = Rotation.from_rotvec(rotvecs).as_quat()
        angles = euler_from_quats(quats, order)
        assert rotation_gap(quats_from_euler(angles, order), quats) < 1e-9
        steps = np.abs(np.diff(angles, axis=0))
        assert np.max(steps) < np.pi, f"jump of {np.rad2deg(np.max(steps)):.1f} degrees"


def test_batched_joints_convert_like_single_ones() -> None:
    rng = np.random.default_rng(11)
    angles = rng.uniform(-np.pi, np.pi, size=(30, 5, 3))
    quats = quats_from_euler(angles, "ZXY")
    assert quats.shape == (30, 5, 4)
    back = euler_from_quats(quats, "ZXY")
    assert back.shape == (30, 5, 3)
    for j in range(5):
        np.testing.assert_allclose(back[:, j], euler_from_quats(quats[:, j], "ZXY"))


@pytest.mark.parametrize("order", ["XYX", "xyz", "ZY", ""])
def test_unknown_orders_are_refused(order: str) -> None:
    with pytest.raises(ShapeError, match=r"Expected a rotation order in"):
        quats_from_euler(np.zeros(3), order)
    with pytest.raises(ShapeError, match=r"Expected a rotation order in"):
        euler_from_quats(np.array([[0.0, 0.0, 0.0, 1.0]]), order)
