"""Runs of frames: hysteresis, closing short gaps, dropping short runs, per-run reductions.

Conventions
-----------
* Masks are ``(F, N)``: time on axis 0, N independent series (foot points, feet) on axis 1.
* A run is ``(column, start, end)`` with both frames inside the run (ends inclusive), listed by
  column, then by start.
* Everything is vectorised over frames and columns: hysteresis is a running maximum of the
  last "enter" and the last "break" frame, runs come from the edges of a padded mask, and
  per-run sums and maxima use ``ufunc.reduceat`` on the column-major flattening.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, column_runs
from mocapqa.errors import ShapeError

__all__ = [
    "Runs",
    "close_short_gaps",
    "drop_short_runs",
    "frames_in",
    "hysteresis",
    "paint_runs",
    "run_argmax",
    "run_frames",
    "run_maximum",
    "run_mean",
    "run_median",
]

Runs = tuple[IntArray, IntArray, IntArray]
"""``(columns, starts, ends)`` of the runs of a mask, ends inclusive."""


def _as_2d(mask: BoolArray, name: str) -> BoolArray:
    array = np.asarray(mask, dtype=bool)
    if array.ndim != 2:
        raise ShapeError(f"Expected `{name}` to have shape (F, N), got {array.shape}")
    return array


def hysteresis(enter: BoolArray, stay: BoolArray) -> BoolArray:
    """A two-threshold state: on from a frame where ``enter`` holds for as long as ``stay``
    holds.

    Parameters
    ----------
    enter, stay : ndarray of bool, shape (F, N)
        Where the strict (entry) and the loose (keep) conditions hold. ``enter`` counts only
        where ``stay`` holds too.

    Returns
    -------
    ndarray of bool, shape (F, N)
        True at frame t when some frame s ≤ t satisfies ``enter`` and every frame of
        ``s..t`` satisfies ``stay``.
    """
    stay = _as_2d(stay, "stay")
    enter = _as_2d(enter, "enter") & stay
    frames = np.arange(stay.shape[0])[:, None]
    last_enter = np.maximum.accumulate(np.where(enter, frames, -1), axis=0)
    last_break = np.maximum.accumulate(np.where(stay, -1, frames), axis=0)
    result: BoolArray = last_enter > last_break
    return result


def paint_runs(runs: Runs, shape: tuple[int, int]) -> BoolArray:
    """A ``(F, N)`` mask that is true on the given runs."""
    columns, starts, ends = runs
    delta = np.zeros((shape[1], shape[0] + 1), dtype=np.int32)
    np.add.at(delta, (columns, starts), 1)
    np.add.at(delta, (columns, ends + 1), -1)
    painted: BoolArray = np.cumsum(delta, axis=1)[:, :-1].T > 0
    return painted


def close_short_gaps(mask: BoolArray, max_gap: int) -> BoolArray:
    """``mask`` with every false run of at most ``max_gap`` frames between two true runs
    set true (false runs at the start or end of the take stay)."""
    mask = _as_2d(mask, "mask")
    if max_gap <= 0:
        return mask.copy()
    columns, starts, ends = column_runs(~mask)
    interior = (starts > 0) & (ends < mask.shape[0] - 1) & (ends - starts + 1 <= max_gap)
    gaps = paint_runs((columns[interior], starts[interior], ends[interior]), mask.shape)
    result: BoolArray = mask | gaps
    return result


def drop_short_runs(mask: BoolArray, min_length: int) -> BoolArray:
    """``mask`` without its true runs shorter than ``min_length`` frames."""
    mask = _as_2d(mask, "mask")
    columns, starts, ends = column_runs(mask)
    keep = ends - starts + 1 >= min_length
    return paint_runs((columns[keep], starts[keep], ends[keep]), mask.shape)


def _reduce(ufunc: np.ufunc, values: FloatArray, runs: Runs, pad: float) -> FloatArray:
    columns, starts, ends = runs
    if columns.size == 0:
        return np.zeros(0)
    n_frames = values.shape[0]
    flat = np.append(np.ascontiguousarray(values.T).ravel(), pad)
    first = columns * n_frames + starts
    bounds = np.empty(2 * first.size, dtype=np.intp)
    bounds[0::2] = first
    bounds[1::2] = columns * n_frames + ends + 1
    reduced: FloatArray = ufunc.reduceat(flat, bounds)[0::2]
    return reduced


def run_maximum(values: FloatArray, runs: Runs) -> FloatArray:
    """Maximum of ``values`` ``(F, N)`` over each run (NaN if the run holds a NaN)."""
    return _reduce(np.maximum, np.asarray(values, dtype=np.float64), runs, -np.inf)


def run_mean(values: FloatArray, runs: Runs) -> FloatArray:
    """Mean of ``values`` ``(F, N)`` over each run, NaN values left out (NaN if all are)."""
    array = np.asarray(values, dtype=np.float64)
    valid = np.isfinite(array)
    sums = _reduce(np.add, np.where(valid, array, 0.0), runs, 0.0)
    counts = _reduce(np.add, valid.astype(np.float64), runs, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        means: FloatArray = np.where(counts > 0, sums / np.maximum(counts, 1.0), np.nan)
    return means


def frames_in(seconds: float, fps: float) -> int:
    """Whole frames (at least one) in ``seconds`` at ``fps`` frames per second."""
    return max(1, round(seconds * fps))


def run_frames(runs: Runs) -> tuple[IntArray, IntArray, IntArray]:
    """Every frame of every run, concatenated: ``(frame, column, run index)``, each ``(N,)``
    (runs in their order, frames in order within each)."""
    columns, starts, ends = runs
    lengths = ends - starts + 1
    run_index = np.repeat(np.arange(lengths.size), lengths)
    offsets = np.arange(int(lengths.sum())) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    return starts[run_index] + offsets, columns[run_index], run_index


def run_argmax(values: FloatArray, run_index: IntArray, n_runs: int) -> tuple[FloatArray, IntArray]:
    """Largest value of ``values`` ``(N,)`` per run and its position in the concatenated
    order of :func:`run_frames` (NaN and inf left out, −inf for a run with none: its first
    position); ``run_index`` is sorted and every run has a frame."""
    filled = np.where(np.isfinite(values), values, -np.inf)
    if n_runs == 0:
        return filled[:0], np.zeros(0, dtype=np.intp)
    # Runs are contiguous and never empty: reduce over each, then its first row at the top.
    firsts = np.searchsorted(run_index, np.arange(n_runs))
    top = np.maximum.reduceat(filled, firsts)
    rows = np.where(filled == top[run_index], np.arange(filled.size), filled.size)
    where = np.minimum.reduceat(rows, firsts)
    return filled[where], where


def run_median(values: FloatArray, run_index: IntArray) -> FloatArray:
    """Lower median of ``values`` (N,) per run, NaN values left out (NaN for a run with none).

    ``run_index`` is sorted (runs are contiguous), as :func:`run_frames` gives it.
    """
    n_runs = int(run_index[-1]) + 1 if run_index.size else 0
    valid = np.isfinite(values)
    # One float sort instead of a lexsort: each run's values scaled into [0, 0.5] and added
    # to its index (the missing ones at 0.75, after them), so runs stay apart and in order.
    low, high = (float(v.min()), float(v.max())) if (v := values[valid]).size else (0.0, 0.0)
    scale = 0.5 / (high - low) if high > low else 0.0
    keys = run_index + np.where(valid, (np.where(valid, values, low) - low) * scale, 0.75)
    order = np.argsort(keys)
    counts = np.bincount(run_index[valid], minlength=n_runs)
    firsts = np.searchsorted(run_index, np.arange(n_runs))
    middle = firsts + np.maximum(counts - 1, 0) // 2
    medians: FloatArray = np.where(counts > 0, values[order][np.minimum(middle, len(values) - 1)],
                                   np.nan)  # fmt: skip
    return medians
