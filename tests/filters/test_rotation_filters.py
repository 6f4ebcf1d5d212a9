"""Quaternion PD, quaternion One Euro, Euler PD and Butterworth on rotation streams."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from mocapqa.errors import InputError
from mocapqa.filters.butterworth import ButterworthParams, butterworth_quats
from mocapqa.filters.euler_pd import euler_pd_filter, vector_pd_filter
from mocapqa.filters.quat_one_euro import QuatOneEuroFilter, QuatOneEuroParams, quat_one_euro_filter
from mocapqa.filters.quat_pd import (
    QuatPDFilter,
    QuatPDParams,
    max_stable_frequency_hz,
    quat_pd_filter,
)
from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.quaternion import geodesic_angle, unwrap
from mocapqa_bench.filters import Take
from mocapqa_bench.rotation_filters import clean_change_table


def _noisy_walk(n: int, joints: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    rotvecs = np.cumsum(rng.normal(scale=0.03, size=(n, joints, 3)), axis=0)
    truth = Rotation.from_rotvec(rotvecs.reshape(-1, 3)).as_quat().reshape(n, joints, 4)
    noise = Rotation.from_rotvec(rng.normal(scale=0.05, size=(n * joints, 3)))
    noisy = (noise * Rotation.from_quat(truth.reshape(-1, 4))).as_quat().reshape(n, joints, 4)
    signs = np.where(rng.random((n, joints, 1)) < 0.5, -1.0, 1.0)
    return truth, noisy * signs


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_constant_rotation_comes_back_unchanged_whatever_its_sign(seed: int) -> None:
    q = Rotation.random(3, rng=np.random.default_rng(seed)).as_quat()
    signs = np.where(np.random.default_rng(seed + 1).random((12, 3, 1)) < 0.5, -1.0, 1.0)
    x = np.broadcast_to(q, (12, 3, 4)) * signs
    for out in (
        quat_pd_filter(x, 30.0, QuatPDParams()),
        quat_pd_filter(x, 30.0, QuatPDParams(integration="approximate", accel_gain=0.5)),
        quat_one_euro_filter(x, 30.0, QuatOneEuroParams()),
        butterworth_quats(x, 30.0, ButterworthParams(3.0)),
    ):
        # arccos near 1 turns rounding of 1e-16 into ~1e-6°.
        assert np.degrees(geodesic_angle(out, x)).max() < 1e-4


def test_unit_quaternions_stay_unit_and_noise_is_reduced() -> None:
    truth, noisy = _noisy_walk(150, 4, 0)
    raw = geodesic_angle(noisy, truth).mean()
    for out in (
        quat_pd_filter(noisy, 30.0, QuatPDParams(natural_frequency_hz=2.0)),
        quat_one_euro_filter(noisy, 30.0, QuatOneEuroParams()),
        butterworth_quats(noisy, 30.0, ButterworthParams(4.0)),
    ):
        np.testing.assert_allclose(np.linalg.norm(out, axis=-1), 1.0, atol=1e-12)
        assert geodesic_angle(out, truth).mean() < raw


def test_exact_integration_step_matches_scipy() -> None:
    # One step from rest toward a 30° error: ω = Δt κP vec(q̂ q*), then q ← exp(Δt ω) q.
    target = Rotation.from_rotvec([0.0, 0.0, np.radians(30)]).as_quat()
    start = np.array([0.0, 0.0, 0.0, 1.0])
    p = QuatPDParams(natural_frequency_hz=2.0, damping_ratio=0.8)
    f = QuatPDFilter(p, 1, 30.0)
    f.update(start[None])
    out = f.update(target[None])[0]
    omega = (1 / 30.0) * f.kp * target[:3]
    expected = (Rotation.from_rotvec(omega / 30.0) * Rotation.from_quat(start)).as_quat()
    assert np.degrees(geodesic_angle(out, expected)) < 1e-9


def test_exact_and_approximate_integration_are_close() -> None:
    _, noisy = _noisy_walk(120, 3, 1)
    exact = quat_pd_filter(noisy, 30.0, QuatPDParams())
    approx = quat_pd_filter(noisy, 30.0, QuatPDParams(integration="approximate"))
    assert np.degrees(geodesic_angle(exact, approx)).max() < 0.5


def test_streaming_equals_batch() -> None:
    _, noisy = _noisy_walk(60, 5, 2)
    p = QuatPDParams(accel_gain=0.3)
    f = QuatPDFilter(p, 5, 30.0)
    stream = unwrap(np.array([f.update(q) for q in noisy]))
    np.testing.assert_array_equal(stream, quat_pd_filter(noisy, 30.0, p))
    g = QuatOneEuroFilter(QuatOneEuroParams(), 5, 30.0)
    stream = unwrap(np.array([g.update(q) for q in noisy]))
    np.testing.assert_array_equal(stream, quat_one_euro_filter(noisy, 30.0, QuatOneEuroParams()))


def test_unstable_gains_are_refused_or_clamped() -> None:
    limit = max_stable_frequency_hz(1.0, 30.0)
    # Semi-implicit Euler: h²ω² + 4ζhω < 4 → hω = 2(√2 − 1) for ζ = 1.
    assert limit == pytest.approx(2 * (np.sqrt(2) - 1) * 30 / (2 * np.pi))
    x = np.broadcast_to(np.array([0.0, 0.0, 0.0, 1.0]), (5, 1, 4))
    with pytest.raises(InputError, match=r"Expected `natural_frequency_hz` < 3\.96 Hz"):
        quat_pd_filter(x, 30.0, QuatPDParams(natural_frequency_hz=5.0))
    clamped = quat_pd_filter(x, 30.0, QuatPDParams(natural_frequency_hz=5.0, on_unstable="clamp"))
    assert np.isfinite(clamped).all()


def test_euler_pd_handles_wrap_around_at_180_degrees() -> None:
    # A steady yaw through ±180°: the unwrapped Euler PD must not jump the long way round.
    yaw = np.radians(np.linspace(150, 210, 61))
    quats = Rotation.from_euler("ZXY", np.stack([yaw, 0 * yaw, 0 * yaw], 1)).as_quat()[:, None]
    out = euler_pd_filter(quats, ["ZXY"], 30.0, QuatPDParams(natural_frequency_hz=3.0))
    assert np.degrees(geodesic_angle(out, quats)).max() < 5.0


def test_vector_pd_tracks_a_step_without_overshoot_when_critically_damped() -> None:
    x = np.r_[np.zeros(5), np.ones(60)][:, None]
    out = vector_pd_filter(x, 30.0, QuatPDParams(natural_frequency_hz=2.0, damping_ratio=1.0))
    assert out.max() <= 1.0 + 1e-9
    assert out[-1, 0] == pytest.approx(1.0, abs=1e-3)


def test_clean_takes_measure_each_filters_lag(corpus_dir: Path) -> None:
    # A real walk and kick as recorded (no noise): the zero-phase offline filter changes them
    # least, and every causal filter changes them by a measurable lag.
    names = ["dataset-2_walk_normal_001.bvh", "dataset-1_kick_normal_001.bvh"]
    takes = [
        Take(n, read_bvh(corpus_dir / "bvh" / "bandai" / n), np.zeros((0, 0, 3))) for n in names
    ]
    rows = {r["method"]: r for r in clean_change_table(takes)}
    assert set(rows) == {"quat-pd", "quat-one-euro", "euler-pd", "butterworth"}
    for method in ("quat-pd", "quat-one-euro", "euler-pd"):
        assert rows["butterworth"]["median change °"] < rows[method]["median change °"]
        assert rows[method]["95th percentile °"] > 1.0
    assert all(0.0 <= r["median change °"] <= r["95th percentile °"] for r in rows.values())
