"""Smoothed tracks and speeds of points over time, and heights along an up axis.

Conventions
-----------
* Arrays are ``(F, P, 3)`` positions in take units; time is axis 0; speeds are take units per
  second.
* Smoothing is a centred moving average whose window shrinks at the take's ends; NaN samples
  are left out of their neighbours' averages and stay NaN themselves, so a keypoint gap never
  becomes invented positions.
* Speed is the central difference of the smoothed track (one-sided at the ends): the window
  (about 0.1 s) keeps detector jitter of a few millimetres from reading as motion while a
  foot's landing still shows within a few frames.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray

__all__ = ["horizontal_axes", "moving_average", "norms", "smoothing_window", "velocities"]


def smoothing_window(fps: float, seconds: float) -> int:
    """An odd window of at least 3 frames spanning about ``seconds`` at ``fps``."""
    frames = max(3, round(seconds * fps))
    return frames if frames % 2 else frames + 1


def moving_average(values: FloatArray, window: int) -> FloatArray:
    """Centred moving average along axis 0, NaN-aware.

    Parameters
    ----------
    values : ndarray, shape (F, ...)
    window : int
        Odd number of frames; the window shrinks to the frames available at the ends.

    Returns
    -------
    ndarray, shape (F, ...)
        NaN where ``values`` is NaN.
    """
    array = np.asarray(values, dtype=np.float64)
    n_frames = array.shape[0]
    if n_frames == 0 or window <= 1:
        return array.copy()
    half = window // 2
    valid = np.isfinite(array)
    if valid.all():
        # No gaps: the frame counts are known, and slices replace the gathers.
        sums = np.cumsum(array, axis=0)
        sums = np.concatenate([np.zeros_like(sums[:1]), sums])
        frames = np.arange(n_frames)
        hi = np.minimum(frames + half + 1, n_frames)
        lo = np.maximum(frames - half, 0)
        counts = (hi - lo).astype(np.float64).reshape((-1,) + (1,) * (array.ndim - 1))
        out = np.empty_like(array)
        if n_frames > 2 * half:
            out[half : n_frames - half] = sums[2 * half + 1 :] - sums[: n_frames - 2 * half]
        edges = np.flatnonzero((frames < half) | (frames >= n_frames - half))
        out[edges] = sums[hi[edges]] - sums[lo[edges]]
        mean: FloatArray = out / counts
        return mean
    zeroed = np.where(valid, array, 0.0)
    pad = [(1, 0)] + [(0, 0)] * (array.ndim - 1)
    sums = np.pad(np.cumsum(zeroed, axis=0), pad)
    counts = np.pad(np.cumsum(valid, axis=0, dtype=np.float64), pad)
    hi = np.minimum(np.arange(n_frames) + half + 1, n_frames)
    lo = np.maximum(np.arange(n_frames) - half, 0)
    total = sums[hi] - sums[lo]
    count = counts[hi] - counts[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(valid, total / np.maximum(count, 1.0), np.nan)
    return mean


def velocities(positions: FloatArray, fps: float) -> FloatArray:
    """Velocity of each point, ``(F, ...)``, take units per second (central differences;
    zero for a one-frame take)."""
    array = np.asarray(positions, dtype=np.float64)
    if array.shape[0] < 2:
        return np.zeros_like(array)
    gradient: FloatArray = np.gradient(array, axis=0) * fps
    return gradient


def horizontal_axes(up_axis: int) -> tuple[int, int]:
    """The two coordinate axes other than ``up_axis``, in increasing order."""
    first, second = (a for a in range(3) if a != up_axis)
    return first, second


def norms(vectors: FloatArray) -> FloatArray:
    """Euclidean length over the last axis (``np.linalg.norm(v, axis=-1)``, in one pass)."""
    lengths: FloatArray = np.sqrt(np.einsum("...k,...k->...", vectors, vectors))
    return lengths
