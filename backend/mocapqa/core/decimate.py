"""The frames a plotted run keeps: every peak of every series, within a number of samples.

A run's plotted series (twist θP and offsets, limits distances, filter weights) share one frame
axis. :func:`peak_frames` chooses it by the min–max rule the dashboard uses for its pixel
columns (``frontend/js/decimate.js``): the frames are cut into buckets of equal width, and each
bucket keeps its first frame and, for every series, its lowest and highest sample and its first
missing (NaN) one, so a one-frame spike is never dropped and a gap stays a gap. Frames the caller
must show (a finding's edges) come first, most important first, as the take's first and last
frames; the bucket width is then the narrowest that keeps the total within ``max_points``, so
the buckets widen as findings take the samples. A reported finding is never dropped for the
shape of a curve.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, check_shape
from mocapqa.errors import InputError

__all__ = ["bucket_extremes", "peak_frames", "sample_frames"]


def sample_frames(n_frames: int, max_points: int) -> IntArray:
    """Evenly spaced frame indices, at most ``max_points`` of them, always the first and last.

    Parameters
    ----------
    n_frames : int
        Frames in the take.
    max_points : int
        Largest number of samples.

    Returns
    -------
    ndarray, shape (S,)
        Increasing frame indices.
    """
    if n_frames <= max_points:
        return np.arange(n_frames, dtype=np.intp)
    return np.unique(np.linspace(0, n_frames - 1, max_points).round().astype(np.intp))


def bucket_extremes(signals: FloatArray, width: int) -> IntArray:
    """Per bucket of ``width`` frames: its first frame and each signal's extremes and first gap.

    Parameters
    ----------
    signals : ndarray, shape (F, S)
        S series sampled on every frame (any unit; NaN where missing).
    width : int
        Frames per bucket (≥ 1); the last bucket may be shorter.

    Returns
    -------
    ndarray, shape (K,)
        Increasing frame indices: the first frame of every bucket and, per bucket and series,
        the frame of the lowest and of the highest sample and of the first NaN (if any). A
        bucket where a series is all NaN keeps that series' first frame only.
    """
    check_shape(signals, "signals", ("F", "S"))
    if width < 1:
        raise InputError(f"Expected width ≥ 1, got {width}")
    return _extremes(*_prepared(signals), width)


def _prepared(signals: FloatArray) -> tuple[FloatArray, FloatArray, BoolArray]:
    gaps = np.isnan(signals)
    return np.where(gaps, np.inf, signals), np.where(gaps, -np.inf, signals), gaps


def _extremes(lowered: FloatArray, raised: FloatArray, gaps: BoolArray, width: int) -> IntArray:
    # The full buckets are views of the arrays; the shorter last bucket is its own block.
    n_frames, n_series = lowered.shape
    full = n_frames // width * width
    picks = [np.arange(0, n_frames, width, dtype=np.intp)]
    for start, stop in ((0, full), (full, n_frames)):
        size = width if start == 0 else stop - start
        if stop <= start:
            continue
        n_blocks = (stop - start) // size
        shape = (n_blocks, size, n_series)
        base = start + size * np.arange(n_blocks, dtype=np.intp)[:, None]
        holes = gaps[start:stop].reshape(shape)
        picks += [
            (base + lowered[start:stop].reshape(shape).argmin(axis=1)).ravel(),
            (base + raised[start:stop].reshape(shape).argmax(axis=1)).ravel(),
            (base + holes.argmax(axis=1))[holes.any(axis=1)],
        ]
    frames: IntArray = np.unique(np.concatenate(picks)).astype(np.intp)
    return frames


def _kept(n_frames: int, room: int, keep: IntArray) -> IntArray:
    inside = keep[(keep >= 0) & (keep < n_frames)]
    _, first = np.unique(inside, return_index=True)
    ordered = inside[np.sort(first)]  # each frame once, at its highest priority
    ends = np.array([0, n_frames - 1], dtype=np.intp)
    ordered = ordered[~np.isin(ordered, ends)]
    return np.union1d(ends, ordered[: max(0, room - 2)]).astype(np.intp)


def peak_frames(signals: FloatArray, max_points: int, keep: IntArray | None = None) -> IntArray:
    """The frames a plot of ``signals`` keeps: every bucket's extremes, within ``max_points``.

    Parameters
    ----------
    signals : ndarray, shape (F, S)
        The plotted series on every frame (any unit; NaN where missing). S may be 0.
    max_points : int
        Largest number of frames returned (≥ 2).
    keep : ndarray of int, shape (K,), optional
        Frames to keep (findings' edges), most important first; frames outside ``[0, F)``
        are ignored.

    Returns
    -------
    ndarray, shape (N,)
        Increasing frame indices, ``N ≤ max_points``. A take of at most ``max_points`` frames
        keeps every frame. Otherwise: the first and last frames; then the frames of ``keep``
        in order, as many as fit (a take with more findings than samples keeps the first
        ones); then
        :func:`bucket_extremes` at the narrowest bucket width, found by bisection, whose union
        with those fits. If even one bucket for the whole take does not fit (more series than
        samples), evenly spaced frames fill the rest.
    """
    check_shape(signals, "signals", ("F", "S"))
    if max_points < 2:
        raise InputError(f"Expected max_points ≥ 2, got {max_points}")
    n_frames, n_series = signals.shape
    if n_frames <= max_points:
        return np.arange(n_frames, dtype=np.intp)
    wanted = np.empty(0, dtype=np.intp) if keep is None else np.asarray(keep, dtype=np.intp)
    required = _kept(n_frames, max_points, wanted)
    room = max_points - required.size

    prepared = _prepared(signals)

    def kept(width: int) -> IntArray:
        return np.union1d(required, _extremes(*prepared, width)).astype(np.intp)

    # Each bucket adds at most 1 + 3 S frames: this width always fits when room allows it.
    per_bucket = 1 + 3 * n_series
    low = -(-n_frames // max_points)
    high = n_frames if room < per_bucket else max(low, -(-n_frames // (room // per_bucket)))
    best = kept(high)
    if best.size > max_points:
        return np.union1d(required, sample_frames(n_frames, room)).astype(np.intp)
    while low < high:
        middle = (low + high) // 2
        frames = kept(middle)
        if frames.size <= max_points:
            high, best = middle, frames
        else:
            low = middle + 1
    return best
