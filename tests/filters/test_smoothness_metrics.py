"""Smoothness and lag metrics on signals with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from mocapqa.metrics.smoothness import (
    acceleration_error,
    jitter_score,
    lag_frames,
    mean_abs_jerk,
    rmse,
)


def test_jerk_of_a_cubic_is_six_times_its_leading_coefficient() -> None:
    t = np.arange(50) / 30.0
    assert mean_abs_jerk(2.0 * t**3, 30.0) == pytest.approx(12.0, rel=1e-6)


def test_lag_of_a_delayed_signal_is_found_to_sub_frame_accuracy() -> None:
    t = np.arange(300) / 30.0
    ref = np.sin(2 * np.pi * 0.7 * t)[:, None]
    late = np.sin(2 * np.pi * 0.7 * (t - 2.5 / 30.0))[:, None]
    assert lag_frames(ref, late) == pytest.approx(2.5, abs=0.1)
    assert lag_frames(late, ref) == pytest.approx(-2.5, abs=0.1)


def test_rmse_accel_and_jitter_on_simple_inputs() -> None:
    a = np.zeros((10, 2, 3))
    b = a.copy()
    b[..., 0] = 3.0
    b[..., 1] = 4.0
    assert rmse(b, a) == pytest.approx(5.0)
    assert acceleration_error(b, a) == pytest.approx(0.0)
    assert jitter_score(np.array([0.0, 1.0, 0.0, 1.0, 0.0])) == 1.0
    assert jitter_score(np.arange(6.0)) == 0.0


@pytest.mark.parametrize("n_frames", [0, 1, 2, 3])
def test_lag_of_a_take_too_short_to_correlate_is_nan(n_frames: int) -> None:
    # Fewer than 4 frames give fewer than 3 differences: no shift can be compared.
    values = np.arange(n_frames * 6, dtype=np.float64).reshape(n_frames, 2, 3)
    assert np.isnan(lag_frames(values, values + 1.0))


def test_lag_of_still_signals_is_nan_not_the_largest_shift() -> None:
    still = np.ones((40, 3))
    assert np.isnan(lag_frames(still, still))
    gap = np.full((40, 3), np.nan)
    assert np.isnan(lag_frames(gap, gap))
