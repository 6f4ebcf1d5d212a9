"""Offline bridging of keypoint gaps: interpolated inside the take, held at its ends.

Conventions
-----------
A keypoint's gap is a run of frames without a detection (NaN, which every reader makes of a
zero-confidence detection). A gap between two detections is filled by linear interpolation
between them; a gap before the first or after the last detection holds that detection; a
keypoint never detected stays NaN. Nothing is extrapolated, so a filled value lies within the
range of the keypoint's detections on every axis, and pixel data (whose detections lie in the
image) stay inside the image. :func:`clamp_to_detections` keeps any other estimated value (a
filter's prediction over a rejected sample) within that range too. Arrays are ``(F, K, ...)``
with time on axis 0 and a mask ``(F, K)``.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.errors import ShapeError

__all__ = ["clamp_to_detections", "fill_gaps", "gap_neighbours"]


def _check_mask(values: FloatArray, missing: BoolArray) -> None:
    if values.shape[: missing.ndim] != missing.shape:
        raise ShapeError(
            f"Expected a mask of shape {values.shape[: missing.ndim]} for values of shape "
            f"{values.shape}, got {missing.shape}"
        )


def gap_neighbours(missing: BoolArray) -> tuple[IntArray, IntArray]:
    """The nearest detected frame at or before, and at or after, every frame.

    Parameters
    ----------
    missing : ndarray of bool, shape (F, ...)
        True where there is no detection.

    Returns
    -------
    before, after : ndarray of int, shape (F, ...)
        The frame itself where detected; else the last detected frame before it (-1 when none)
        and the first after it (F when none).
    """
    missing = np.asarray(missing, dtype=bool)
    n = missing.shape[0]
    frames = np.arange(n).reshape((n,) + (1,) * (missing.ndim - 1))
    before = np.maximum.accumulate(np.where(missing, -1, frames), axis=0)
    after = np.flip(
        np.minimum.accumulate(np.flip(np.where(missing, n, frames), axis=0), axis=0), axis=0
    )
    return before.astype(np.intp), after.astype(np.intp)


def fill_gaps(values: FloatArray, missing: BoolArray) -> FloatArray:
    """Fill the missing samples: interpolated between detections, held at the take's ends.

    Parameters
    ----------
    values : ndarray, shape (F, K, ...)
        Samples; those under ``missing`` are replaced (whatever they hold).
    missing : ndarray of bool, shape (F, K)
        True where a keypoint has no detection.

    Returns
    -------
    ndarray, shape (F, K, ...)
        A copy: a missing sample between two detections lies on the straight line between
        them, one before the first (after the last) detection holds it, and a keypoint with no
        detection at all keeps its values.

    Raises
    ------
    ShapeError
        If ``missing`` is not the leading shape of ``values``.
    """
    values = np.asarray(values, dtype=np.float64)
    missing = np.asarray(missing, dtype=bool)
    _check_mask(values, missing)
    n = values.shape[0]
    if n == 0 or not missing.any():
        return values.copy()
    before, after = gap_neighbours(missing)
    seen = (before >= 0) | (after < n)
    start = np.clip(np.where(before >= 0, before, after), 0, n - 1)
    end = np.clip(np.where(after < n, after, before), 0, n - 1)
    frames = np.arange(n).reshape((n,) + (1,) * (missing.ndim - 1))
    span = end - start
    weight = np.where(span > 0, (frames - start) / np.maximum(span, 1), 0.0)
    extra = (1,) * (values.ndim - missing.ndim)
    first = np.take_along_axis(values, start.reshape(start.shape + extra), axis=0)
    last = np.take_along_axis(values, end.reshape(end.shape + extra), axis=0)
    filled = first + weight.reshape(weight.shape + extra) * (last - first)
    replace = (missing & seen).reshape(missing.shape + extra)
    return np.asarray(np.where(replace, filled, values))


def clamp_to_detections(values: FloatArray, detections: FloatArray, where: BoolArray) -> FloatArray:
    """Keep estimated samples within the range of their keypoint's detections.

    Parameters
    ----------
    values : ndarray, shape (F, K, D)
        Samples, some of them estimated.
    detections : ndarray, shape (F, K, D)
        The detections, NaN where missing.
    where : ndarray of bool, shape (F, K)
        The estimated samples, the only ones changed.

    Returns
    -------
    ndarray, shape (F, K, D)
        A copy, each estimated sample clipped per axis to its keypoint's smallest and largest
        detection (unchanged for a keypoint never detected).

    Raises
    ------
    ShapeError
        If the shapes differ.
    """
    values = np.asarray(values, dtype=np.float64)
    detections = np.asarray(detections, dtype=np.float64)
    if values.shape != detections.shape:
        raise ShapeError(f"Expected detections of shape {values.shape}, got {detections.shape}")
    where = np.asarray(where, dtype=bool)
    _check_mask(values, where)
    seen = ~np.isnan(detections)
    low = np.where(seen, detections, np.inf).min(axis=0, initial=np.inf)
    high = np.where(seen, detections, -np.inf).max(axis=0, initial=-np.inf)
    clipped = np.where(np.isfinite(low), np.clip(values, low, high), values)
    extra = (1,) * (values.ndim - where.ndim)
    return np.asarray(np.where(where.reshape(where.shape + extra), clipped, values))
