"""Quaternion operations against scipy's Rotation; unwrap keeps every rotation."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from kinematics_strategies import unit_quats
from scipy.spatial.transform import Rotation

from mocapqa.kinematics.quaternion import (
    canonical,
    conjugate,
    exp_map,
    geodesic_angle,
    log_map,
    multiply,
    quats_wxyz_from_xyzw,
    quats_xyzw_from_wxyz,
    rotate,
    unwrap,
)


def test_multiply_and_rotate_match_scipy() -> None:
    rng = np.random.default_rng(5)
    p = Rotation.random(500, random_state=rng)
    q = Rotation.random(500, random_state=rng)
    vectors = rng.normal(size=(500, 3))
    np.testing.assert_allclose(
        canonical(multiply(p.as_quat(), q.as_quat())), canonical((p * q).as_quat()), atol=1e-12
    )
    np.testing.assert_allclose(rotate(p.as_quat(), vectors), p.apply(vectors), atol=1e-12)
    np.testing.assert_allclose(
        canonical(conjugate(p.as_quat())), canonical(p.inv().as_quat()), atol=1e-15
    )
    angles = geodesic_angle(p.as_quat(), q.as_quat())
    np.testing.assert_allclose(angles, (p.inv() * q).magnitude(), atol=1e-12)
    np.testing.assert_allclose(geodesic_angle(p.as_quat(), p.as_quat()), 0.0, atol=1e-15)
    np.testing.assert_allclose(geodesic_angle(p.as_quat(), -p.as_quat()), 0.0, atol=1e-15)


def test_exp_and_log_maps_match_scipy_rotation_vectors() -> None:
    rng = np.random.default_rng(6)
    rotvecs = rng.normal(size=(300, 3))
    rotvecs *= (rng.uniform(0, np.pi, 300) / np.linalg.norm(rotvecs, axis=1))[:, None]
    quats = exp_map(rotvecs)
    np.testing.assert_allclose(
        canonical(quats), canonical(Rotation.from_rotvec(rotvecs).as_quat()), atol=1e-12
    )
    np.testing.assert_allclose(log_map(quats), rotvecs, atol=1e-9)


def test_scalar_first_converters_are_inverse() -> None:
    xyzw = np.array([[0.1, 0.2, 0.3, 0.9]])
    wxyz = quats_wxyz_from_xyzw(xyzw)
    np.testing.assert_array_equal(wxyz, [[0.9, 0.1, 0.2, 0.3]])
    np.testing.assert_array_equal(quats_xyzw_from_wxyz(wxyz), xyzw)


@settings(deadline=None, max_examples=100)
@given(
    quats=st.lists(unit_quats(), min_size=1, max_size=40),
    flips=st.lists(st.booleans(), min_size=40, max_size=40),
)
def test_unwrap_never_changes_a_rotation(quats: list[np.ndarray], flips: list[bool]) -> None:
    sequence = np.array(quats) * np.where(flips[: len(quats)], -1.0, 1.0)[:, None]
    before = sequence.copy()
    unwrapped = unwrap(sequence)
    np.testing.assert_array_equal(sequence, before)  # input untouched
    # Each element is the same quaternion or its negative: the same rotation.
    same = np.all(unwrapped == sequence, axis=-1) | np.all(unwrapped == -sequence, axis=-1)
    assert np.all(same)
    # ... and consecutive elements share a hemisphere.
    assert np.all(np.sum(unwrapped[1:] * unwrapped[:-1], axis=-1) >= 0.0)


def test_unwrap_works_along_a_chosen_axis() -> None:
    rng = np.random.default_rng(9)
    quats = Rotation.random(60, random_state=rng).as_quat().reshape(3, 20, 4)
    quats *= np.where(rng.random((3, 20, 1)) < 0.5, -1.0, 1.0)
    along_time = unwrap(quats, axis=1)
    assert np.all(np.sum(along_time[:, 1:] * along_time[:, :-1], axis=-1) >= 0.0)
    np.testing.assert_array_equal(np.abs(along_time), np.abs(quats))
