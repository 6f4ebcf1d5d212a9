"""Accuracy, smoothness and lag of filtered trajectories.

Conventions
-----------
Arrays are ``(F, ...)`` with time on axis 0; NaN samples are left out of means. Jerk is the
third difference times ``fps³`` (unit/s³); acceleration error is the mean Euclidean norm of the
difference between second differences (unit/frame², QuaMo's "Accel"); lag is the shift, in
frames (sub-frame by a parabola through the peak), that maximises the cross-correlation of
the first differences of the two signals summed over channels; positive means the second
signal trails the first. Differences are used instead of raw positions so that slow drifts do
not dominate the correlation (the note correlates raw positions). A mean over no finite sample
(a take of a few frames, a keypoint never seen) is NaN, without numpy's "Mean of empty slice"
warning. A metric that needs more frames than the take has (jerk: 4, lag: 4) is NaN, "not
available", as is the lag of signals that do not move (no correlation peak to find).
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray

__all__ = [
    "MIN_FRAMES",
    "acceleration_error",
    "jitter_score",
    "lag_frames",
    "mean_abs_jerk",
    "mean_distance",
    "rmse",
]

MIN_FRAMES = 4
"""Frames the jerk and lag metrics need (three differences); shorter takes give NaN."""


def _nanmean(values: Any, axis: int | None = None) -> Any:
    """``np.nanmean``, NaN where a slice has no finite sample, without the warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(values, axis=axis)


def rmse(estimate: FloatArray, truth: FloatArray, mask: FloatArray | None = None) -> float:
    """Root mean squared Euclidean error of ``(F, K, D)`` points, where ``mask`` (F, K) is set."""
    sq = np.sum((np.asarray(estimate) - np.asarray(truth)) ** 2, axis=-1)
    if mask is not None:
        sq = sq[np.asarray(mask, dtype=bool)]
    return float(np.sqrt(_nanmean(sq))) if sq.size else float("nan")


def mean_distance(estimate: FloatArray, truth: FloatArray) -> float:
    """Mean Euclidean distance of ``(F, K, D)`` points (MPJPE when ``K`` are joints)."""
    return float(_nanmean(np.linalg.norm(np.asarray(estimate) - np.asarray(truth), axis=-1)))


def mean_abs_jerk(values: FloatArray, fps: float) -> float:
    """Mean absolute third difference × ``fps³`` over all channels of ``(F, ...)``, unit/s³."""
    values = np.asarray(values, dtype=np.float64)
    if values.shape[0] < MIN_FRAMES:
        return float("nan")
    return float(_nanmean(np.abs(np.diff(values, n=3, axis=0)))) * fps**3


def acceleration_error(estimate: FloatArray, truth: FloatArray) -> float:
    """Mean ``|Δ²estimate − Δ²truth|`` (Euclidean over the last axis), unit/frame²."""
    d = np.diff(np.asarray(estimate), n=2, axis=0) - np.diff(np.asarray(truth), n=2, axis=0)
    return float(_nanmean(np.linalg.norm(d, axis=-1)))


def jitter_score(values: FloatArray) -> float:
    """Share of direction reversals ``sign(Δx_{t+1}) ≠ sign(Δx_t)`` over all channels, [0, 1]."""
    d = np.diff(np.asarray(values, dtype=np.float64), axis=0)
    return float(_nanmean(d[1:] * d[:-1] < 0)) if d.shape[0] > 1 else 0.0


def lag_frames(reference: FloatArray, signal: FloatArray, max_lag: int = 10) -> float:
    """Lag of ``signal`` behind ``reference`` in frames, from the cross-correlation peak.

    Parameters
    ----------
    reference, signal : ndarray, shape (F, ...)
        Two trajectories of the same shape.
    max_lag : int
        Largest shift searched, frames.

    Returns
    -------
    float
        Sub-frame lag; positive when ``signal`` is late. NaN (not available) for fewer than
        4 frames, where no shift leaves differences to compare, and when the correlation is
        zero at every shift (signals that do not move, or have no finite sample).
    """
    a = np.diff(np.asarray(reference, dtype=np.float64), axis=0)
    b = np.diff(np.asarray(signal, dtype=np.float64), axis=0)
    n = a.shape[0]
    if n < MIN_FRAMES - 1:
        return float("nan")
    a = np.nan_to_num(a.reshape(n, -1) - _nanmean(a.reshape(n, -1), axis=0))
    b = np.nan_to_num(b.reshape(n, -1) - _nanmean(b.reshape(n, -1), axis=0))
    max_lag = max(1, min(max_lag, (n - 1) // 3))
    lags = np.arange(-max_lag, max_lag + 1)
    # One fixed window of the reference for every shift, so a pure delay gives a curve
    # symmetric about the delay and the parabola's vertex is unbiased.
    ref = a[max_lag : n - max_lag]
    corr = np.array([np.sum(ref * b[max_lag + lag : n - max_lag + lag]) for lag in lags])
    if not np.any(corr):
        return float("nan")
    i = int(np.argmax(corr))
    if 0 < i < len(lags) - 1:
        y0, y1, y2 = corr[i - 1], corr[i], corr[i + 1]
        denom = y0 - 2 * y1 + y2
        offset = 0.5 * (y0 - y2) / denom if denom != 0 else 0.0
        return float(lags[i] + offset)
    return float(lags[i])
