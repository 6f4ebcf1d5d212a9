"""Swing–twist exponential map: round trips, the paper's formulas, scipy as the reference."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from mocapqa.limits.expmap import (
    expmap_from_quats,
    limit_params_from_quats,
    quats_from_expmap,
    twist_frames,
)

seeds = st.integers(min_value=0, max_value=2**32 - 1)


def _axes(rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.normal(size=(n, 3))


def _same_rotation(p: np.ndarray, q: np.ndarray, atol: float = 1e-9) -> bool:
    return bool(np.all(np.abs(np.abs(np.sum(p * q, axis=-1)) - 1.0) < atol))


@settings(max_examples=30, deadline=None)
@given(seeds)
def test_quats_survive_a_round_trip_through_the_parameters(seed: int) -> None:
    rng = np.random.default_rng(seed)
    quats = Rotation.random(200, rng=rng).as_quat()
    axes = _axes(rng, 200)
    back = quats_from_expmap(expmap_from_quats(quats, axes), axes)
    assert _same_rotation(back, quats)


@settings(max_examples=30, deadline=None)
@given(seeds)
def test_parameters_survive_a_round_trip_inside_the_chart(seed: int) -> None:
    rng = np.random.default_rng(seed)
    radius = rng.uniform(0.0, np.pi - 1e-3, 200)
    direction = rng.uniform(-np.pi, np.pi, 200)
    tau = rng.uniform(-np.pi + 1e-3, np.pi - 1e-3, 200)
    params = np.column_stack((radius * np.cos(direction), radius * np.sin(direction), tau))
    axes = _axes(rng, 200)
    np.testing.assert_allclose(
        expmap_from_quats(quats_from_expmap(params, axes), axes), params, atol=1e-8
    )


@settings(max_examples=20, deadline=None)
@given(seeds)
def test_parameters_compose_twist_after_swing_as_scipy_does(seed: int) -> None:
    rng = np.random.default_rng(seed)
    axes = _axes(rng, 100)
    frames = twist_frames(axes)
    params = rng.uniform(-1.5, 1.5, (100, 3))
    swing = Rotation.from_rotvec(params[:, :1] * frames[:, 0] + params[:, 1:2] * frames[:, 2])
    twist = Rotation.from_rotvec(params[:, 2:3] * frames[:, 1])
    assert _same_rotation(quats_from_expmap(params, axes), (twist * swing).as_quat())


def test_the_sign_of_a_quaternion_does_not_change_its_parameters() -> None:
    rng = np.random.default_rng(3)
    quats = Rotation.random(500, rng=rng).as_quat()
    axes = _axes(rng, 500)
    np.testing.assert_allclose(expmap_from_quats(-quats, axes), expmap_from_quats(quats, axes))


def test_parameters_match_the_papers_formulas_for_a_y_bone() -> None:
    quats = Rotation.random(1000, rng=np.random.default_rng(4)).as_quat()
    qx, qy, qz, qs = quats.T
    c_zx = np.sqrt(qs**2 + qy**2)
    s_x, s_z = (qs * qx - qy * qz) / c_zx, (qs * qz + qx * qy) / c_zx
    swing = 2 * np.arctan(np.hypot(s_x, s_z) / c_zx)
    expected = np.column_stack(
        (swing * s_x / np.hypot(s_x, s_z), swing * s_z / np.hypot(s_x, s_z), 2 * np.arctan(qy / qs))
    )
    np.testing.assert_allclose(
        expmap_from_quats(quats, np.array([0.0, 1.0, 0.0])), expected, atol=1e-12
    )


def test_a_pure_twist_about_the_bone_has_no_swing() -> None:
    axis = np.array([-1.0, 0.0, 0.0])
    quat = Rotation.from_rotvec(0.7 * axis).as_quat()
    np.testing.assert_allclose(expmap_from_quats(quat, axis), [0.0, 0.0, 0.7], atol=1e-12)


def test_a_half_turn_swing_puts_the_whole_rotation_in_the_swing() -> None:
    quat = Rotation.from_rotvec([np.pi, 0.0, 0.0]).as_quat()
    params = expmap_from_quats(quat, np.array([0.0, 1.0, 0.0]))
    assert params[2] == 0.0
    np.testing.assert_allclose(np.hypot(params[0], params[1]), np.pi)


def test_rotations_at_the_reference_chart_to_the_origin() -> None:
    rng = np.random.default_rng(5)
    refs = Rotation.random(4, rng=rng).as_quat()
    quats = np.broadcast_to(refs, (3, 4, 4))
    params = limit_params_from_quats(quats, _axes(rng, 4), refs)
    np.testing.assert_allclose(params, 0.0, atol=1e-12)
