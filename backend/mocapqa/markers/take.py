"""Checks on a marker take's arrays and the runs of frames they are built from.

Conventions
-----------
* Positions are ``(F, M, 3)`` float64 in the take's length unit, NaN where a marker is
  missing (a sample with any non-finite coordinate is missing).
* A run is ``(marker, start, end)``, frames 0-based with both ends inside the run, listed by
  marker, then start.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, column_runs
from mocapqa.errors import InputError, ShapeError

__all__ = ["Runs", "check_take", "close_breaks", "visible"]

Runs = tuple[IntArray, IntArray, IntArray]
"""``(markers, starts, ends)`` of the runs of a mask, ends inclusive."""


def check_take(positions: FloatArray, names: Sequence[str], fps: float) -> FloatArray:
    """``positions`` as a float64 ``(F, M, 3)`` array, checked against ``names`` and ``fps``.

    Raises
    ------
    ShapeError
        If the shape is not ``(F, M, 3)`` or the names do not match the markers.
    InputError
        If ``fps`` is not a positive finite number.
    """
    array = np.asarray(positions, dtype=np.float64)
    if array.ndim != 3 or array.shape[2] != 3:
        raise ShapeError(f"Expected `positions` to have shape (F, M, 3), got {array.shape}")
    if len(names) != array.shape[1]:
        raise ShapeError(f"Expected {array.shape[1]} marker names, got {len(names)}")
    if not (np.isfinite(fps) and fps > 0):
        raise InputError(f"Expected fps > 0, got {fps!r}")
    return array


def visible(positions: FloatArray) -> BoolArray:
    """``(F, M)`` mask: the samples whose three coordinates are finite."""
    mask: BoolArray = np.asarray(np.isfinite(positions).all(axis=-1))
    return mask


def close_breaks(mask: BoolArray, max_break: int) -> BoolArray:
    """``mask`` ``(F, N)`` with false runs of at most ``max_break`` frames between two true
    runs set true."""
    if max_break <= 0:
        return mask.copy()
    columns, starts, ends = column_runs(~mask)
    inner = (starts > 0) & (ends < mask.shape[0] - 1) & (ends - starts + 1 <= max_break)
    out = mask.copy()
    lengths = ends[inner] - starts[inner] + 1
    if lengths.size:
        offsets = np.arange(int(lengths.sum())) - np.repeat(np.cumsum(lengths) - lengths, lengths)
        out[np.repeat(starts[inner], lengths) + offsets, np.repeat(columns[inner], lengths)] = True
    return out
