"""Kalman, One Euro, EMA and Butterworth on keypoint channels."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from OneEuroFilter import OneEuroFilter as ReferenceOneEuro

from mocapqa.errors import InputError
from mocapqa.filters.butterworth import ButterworthParams, butterworth_filter
from mocapqa.filters.ema import EmaFilter, EmaParams, ema_filter, time_constant_from_alpha
from mocapqa.filters.kalman import KalmanFilter, KalmanParams, kalman_filter
from mocapqa.filters.one_euro import OneEuroParams, one_euro_filter

KALMAN = KalmanParams(process_noise=100.0, measurement_noise=0.01, confidence_weighted=True)


@settings(max_examples=25, deadline=None)
@given(
    value=st.floats(-1e4, 1e4, allow_nan=False),
    fps=st.sampled_from([25.0, 30.0, 60.0, 120.0]),
)
def test_constant_input_comes_back_unchanged(value: float, fps: float) -> None:
    x = np.full((20, 2, 3), value)
    conf = np.full((20, 2, 3), 0.7)
    np.testing.assert_allclose(kalman_filter(x, fps, KALMAN, conf).values, x, atol=1e-9)
    np.testing.assert_allclose(one_euro_filter(x, fps, OneEuroParams())[0], x, atol=1e-9)
    np.testing.assert_allclose(ema_filter(x, fps, EmaParams())[0], x, atol=1e-9)
    np.testing.assert_allclose(butterworth_filter(x, fps, ButterworthParams(3.0))[0], x, atol=1e-6)


def test_one_euro_matches_the_reference_implementation() -> None:
    # The PyPI OneEuroFilter package follows Casiez et al.'s published code.
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(size=200))
    ours = one_euro_filter(x, 60.0, OneEuroParams(1.2, 0.05, 1.0))[0]
    ref = ReferenceOneEuro(60.0, 1.2, 0.05, 1.0)
    expected = [ref(float(v), t / 60.0) for t, v in enumerate(x)]
    np.testing.assert_allclose(ours, expected, rtol=1e-9, atol=1e-9)


def test_kalman_streaming_equals_batch_and_bridges_gaps() -> None:
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.normal(size=(60, 4)), axis=0)
    conf = rng.uniform(0.2, 1.0, size=x.shape)
    x[10:15, 1] = np.nan
    conf[30, 2] = 0.0
    batch = kalman_filter(x, 30.0, KALMAN, conf)
    f = KalmanFilter(KALMAN, 4, 30.0)
    stream = np.array([f.update(x[t], conf[t]) for t in range(60)])
    np.testing.assert_array_equal(stream, batch.values)
    assert not np.isnan(batch.values).any()
    assert batch.bridged[10:15, 1].all()
    assert batch.bridged[30, 2]
    assert not batch.bridged[:10].any()


def test_low_confidence_outlier_pulls_the_kalman_filter_less() -> None:
    x = np.zeros((30, 1))
    x[20] = 10.0
    weak = np.ones((30, 1))
    weak[20] = 0.1
    strong = kalman_filter(x, 30.0, KALMAN, np.ones((30, 1))).values[20, 0]
    damped = kalman_filter(x, 30.0, KALMAN, weak).values[20, 0]
    assert 0 < damped < 0.1 * strong


def test_kalman_gate_rejects_an_outlier_and_reacquires_a_real_jump() -> None:
    p = KalmanParams(100.0, 0.01, gate_sigma=4.0, reacquire_s=0.1)
    x = np.zeros((40, 1))
    x[10] = 50.0
    x[25:] = 50.0
    res = kalman_filter(x, 30.0, p)
    assert res.bridged[10, 0]
    assert abs(res.values[10, 0]) < 1e-9
    assert abs(res.values[-1, 0] - 50.0) < 1.0


def test_ema_time_constant_makes_frame_rates_agree() -> None:
    p = EmaParams(time_constant_s=0.1)
    step30 = ema_filter(np.r_[0.0, np.ones(30)], 30.0, p)[0]
    step120 = ema_filter(np.r_[0.0, np.ones(120)], 120.0, p)[0]
    # After 0.5 s both are at 1 − exp(−5).
    np.testing.assert_allclose(step30[15], step120[60], rtol=1e-9)
    np.testing.assert_allclose(step30[15], 1 - np.exp(-5.0), rtol=1e-9)
    assert time_constant_from_alpha(0.3, 30.0) == pytest.approx(0.09345, rel=1e-3)


def test_ema_streaming_equals_batch() -> None:
    x = np.random.default_rng(1).normal(size=(25, 3))
    f = EmaFilter(EmaParams(), 3, 30.0)
    stream = np.array([f.update(v) for v in x])
    np.testing.assert_array_equal(stream, ema_filter(x, 30.0, EmaParams())[0])


def test_butterworth_interpolates_gaps_and_keeps_empty_channels_marked() -> None:
    x = np.sin(np.linspace(0, 6, 100))[:, None].repeat(2, axis=1)
    x[40:45, 0] = np.nan
    x[:, 1] = np.nan
    out, bridged = butterworth_filter(x, 30.0, ButterworthParams(6.0))
    assert not np.isnan(out[:, 0]).any()
    assert np.isnan(out[:, 1]).all()
    assert bridged[40:45, 0].all()
    assert bridged[:, 1].all()


def test_invalid_parameters_are_refused() -> None:
    with pytest.raises(InputError, match="Expected `process_noise`"):
        KalmanParams(process_noise=0.0)
    with pytest.raises(InputError, match=r"Expected `time_constant_s` 0\.0001 to 60 s"):
        EmaParams(time_constant_s=-1.0)
    with pytest.raises(InputError, match="Nyquist"):
        butterworth_filter(np.zeros((20, 1)), 10.0, ButterworthParams(6.0))
