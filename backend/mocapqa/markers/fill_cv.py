"""Where a gap's cross-validation hides the marker again, and how methods are blended.

A gap's expected error is measured on artificial gaps of the same length hidden in stretches
where the marker is recorded (:func:`trial_starts`). Markers go missing in the hardest moments
(fast motion, occlusion), so the trials are placed where the take moves like it does during the
gap: the gap's *motion* is the mean speed of the markers nearest to the target, which stay
visible over it (:func:`window_motion`), and trials are taken nearest in time to the gap and
nearest in that motion.

:func:`blend_weights` turns each method's cross-validated error into the weights of their
blend (inverse error to a power), and :func:`blend_trial_error` cross-validates the blend
itself, each trial weighted from the other trials' errors only.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray

__all__ = [
    "blend_trial_error",
    "blend_weights",
    "marker_speed_sums",
    "trial_starts",
    "window_motion",
]


def marker_speed_sums(positions: FloatArray, visible: BoolArray) -> tuple[FloatArray, FloatArray]:
    """Running sums of each marker's speed, for the mean speed over any window.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Marker positions (file units), NaN where missing.
    visible : ndarray of bool, shape (F, M)
        Where each marker is seen.

    Returns
    -------
    speed_sum : ndarray, shape (F + 1, M)
        ``speed_sum[f]``: the sum of the distances moved between frames ``i`` and ``i + 1``
        for ``i < f`` where both are seen (file units per frame).
    count_sum : ndarray, shape (F + 1, M)
        The number of those steps.
    """
    n, markers = visible.shape
    step = np.zeros((n, markers))
    seen = np.zeros((n, markers))
    if n > 1:
        both = visible[1:] & visible[:-1]
        moved = np.linalg.norm(np.diff(positions, axis=0), axis=2)
        step[:-1] = np.where(both, moved, 0.0)
        seen[:-1] = both
    zero = np.zeros((1, markers))
    return (
        np.concatenate((zero, np.cumsum(step, axis=0))),
        np.concatenate((zero, np.cumsum(seen, axis=0))),
    )


def window_motion(
    sums: tuple[FloatArray, FloatArray], markers: IntArray, starts: IntArray, length: int
) -> FloatArray:
    """Mean speed of ``markers`` over windows ``s .. s + length - 1`` (file units per frame).

    Parameters
    ----------
    sums : tuple of ndarray, each shape (F + 1, M)
        :func:`marker_speed_sums` of the take.
    markers : ndarray of int, shape (K,)
        The markers whose speed is averaged.
    starts : ndarray of int, shape (S,)
        First frame of each window.
    length : int
        Frames per window.

    Returns
    -------
    ndarray, shape (S,)
        NaN where no step of the markers is seen in a window.
    """
    speed, count = sums
    last = np.minimum(starts + length - 1, speed.shape[0] - 1)
    speed, count = speed[:, markers], count[:, markers]
    moved = (speed[last] - speed[starts]).sum(axis=1)
    steps = (count[last] - count[starts]).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.where(steps > 0, moved / np.maximum(steps, 1), np.nan))


def _one_per_block(ranked: IntArray, length: int, want: int) -> IntArray:
    """The first ``want`` of ``ranked`` with at most one start per block of ``length`` frames."""
    _, first = np.unique(ranked // max(length, 1), return_index=True)
    out: IntArray = ranked[np.sort(first)[:want]]
    return out


def trial_starts(
    ok: BoolArray,
    length: int,
    lead: int,
    tail: int,
    trials: int,
    near: int,
    *,
    local: bool,
    motion: tuple[FloatArray, float] | None = None,
) -> IntArray:
    """Up to ``trials`` starts ``s`` with ``ok`` over ``s - lead .. s + length - 1 + tail``.

    Parameters
    ----------
    ok : ndarray of bool, shape (F,)
        Frames where a trial may hide the marker (and its donors are seen).
    length : int
        Frames per trial.
    lead, tail : int
        Frames before and after a trial that must be ``ok`` too.
    trials : int
        Most trials.
    near : int
        The gap's first frame.
    local : bool
        Take half of the trials (rounded up) nearest to ``near``, at most one per block of
        ``length`` frames (so they hardly overlap); without it, and without ``motion``, all
        are spread evenly over the take.
    motion : tuple of (ndarray, float), optional
        A function of the start, ``motion(s)`` for every frame ``s`` (shape (F,), NaN where
        unknown), and the gap's own value: the remaining trials are those nearest to it in
        log ratio (one per block), rather than spread over the take.

    Returns
    -------
    ndarray of int
        Increasing starts.
    """
    width = lead + length + tail
    if width > ok.size or trials < 1:
        return np.empty(0, dtype=np.intp)
    c = np.concatenate(([0], np.cumsum(ok, dtype=np.int64)))
    starts = np.flatnonzero(c[width:] - c[:-width] == width) + lead
    if starts.size == 0:
        return np.empty(0, dtype=np.intp)
    spread = starts[
        np.linspace(0, starts.size - 1, min(trials, starts.size)).round().astype(np.intp)
    ]
    if not local and motion is None:
        return np.unique(spread).astype(np.intp)
    chosen = np.empty(0, dtype=np.intp)
    if local:
        by_time = starts[np.argsort(np.abs(starts - near), kind="stable")]
        chosen = _one_per_block(by_time, length, (trials + 1) // 2)
    rest = trials - chosen.size
    if motion is not None and rest > 0:
        values, target = motion
        score = np.abs(np.log(np.maximum(values[starts], 1e-12) / max(target, 1e-12)))
        score[~np.isfinite(score)] = np.inf
        left = ~np.isin(starts // max(length, 1), chosen // max(length, 1))
        pool = starts[left][np.argsort(score[left], kind="stable")]
        pool = pool[np.isfinite(np.sort(score[left]))]
        chosen = np.concatenate((chosen, _one_per_block(pool, length, rest)))
        rest = trials - chosen.size
    if rest > 0:
        chosen = np.concatenate((chosen, spread[~np.isin(spread, chosen)][:rest]))
    return np.sort(chosen).astype(np.intp)


def blend_weights(errors: FloatArray, power: float) -> FloatArray:
    """Weights of a blend of methods from their expected errors: ``error ** -power``, summing
    to one.

    Parameters
    ----------
    errors : ndarray, shape (K,)
        Each method's expected error (file units), finite.
    power : float
        Exponent; larger leans harder on the best method.

    Returns
    -------
    ndarray, shape (K,)
        All weight on the exact fills when some error is zero.
    """
    errors = np.asarray(errors, dtype=np.float64)
    if (errors <= 0).any():
        weight = (errors <= 0).astype(np.float64)
    else:
        scaled = errors / errors.min()
        weight = scaled**-power
    out: FloatArray = weight / weight.sum()
    return out


def blend_trial_error(
    squared: FloatArray, fills: FloatArray, truth: FloatArray, power: float
) -> float:
    """Cross-validated RMSE of the blend, each trial weighted from the other trials' errors.

    Parameters
    ----------
    squared : ndarray, shape (T, K)
        Each method's summed squared 3-D error on each trial (file units²).
    fills : ndarray, shape (T, K, L, 3)
        Each method's fill of each trial.
    truth : ndarray, shape (T, L, 3)
        The hidden samples.
    power : float
        As in :func:`blend_weights`.

    Returns
    -------
    float
        RMSE (file units) over every hidden sample; NaN without trials.
    """
    trials, _ = squared.shape
    if trials == 0:
        return float("nan")
    length = truth.shape[1]
    total = squared.sum(axis=0)
    others = total[None, :] - squared if trials > 1 else squared
    count = length * max(trials - 1, 1)
    rmse = np.sqrt(np.maximum(others, 0.0) / count)
    weights = np.stack([blend_weights(row, power) for row in rmse])
    blended = np.einsum("tk,tkld->tld", weights, fills)
    return float(np.sqrt(np.sum((blended - truth) ** 2) / (trials * length)))
