"""Synthetic label swaps for benchmarks and tests.

Each swap exchanges two neighbouring markers' samples over an interval where both are visible
throughout: a marker and one of its rigid mates (:func:`mocapqa.markers.segments.mates`),
or its nearest marker when it has none. Lengths are drawn uniformly in seconds; swaps of one
call share no marker and do not overlap in time, and keep ``margin`` frames apart, so each
is found on its own. Positions are never modified in place.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError
from mocapqa.markers.segments import PairStats, mates, nearest
from mocapqa.markers.take import visible

__all__ = ["InjectedSwap", "inject_swaps"]


@dataclass(frozen=True, slots=True)
class InjectedSwap:
    """The truth of one injected swap: marker indices and frames (0-based, inclusive)."""

    a: int
    b: int
    start: int
    end: int


def inject_swaps(
    positions: FloatArray,
    rng: np.random.Generator,
    stats: PairStats,
    fps: float,
    count: int = 1,
    min_s: float = 0.05,
    max_s: float = 1.0,
    margin: int = 10,
    max_tries: int = 200,
) -> tuple[FloatArray, list[InjectedSwap]]:
    """A copy of ``positions`` with ``count`` swaps between neighbouring markers.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    rng : numpy.random.Generator
    stats : PairStats
        Of the clean take (:func:`mocapqa.markers.segments.pair_stats`): who neighbours whom.
    fps : float
    count : int
        Swaps to inject.
    min_s, max_s : float
        Range of the swap lengths, seconds (at least 1 frame).
    margin : int
        Frames kept between swaps and from the take's ends.
    max_tries : int
        Draws before giving up.

    Returns
    -------
    positions : ndarray, shape (F, M, 3)
    truth : list of InjectedSwap
        By start frame.

    Raises
    ------
    InputError
        If ``count`` swaps cannot be placed in ``max_tries`` draws.
    """
    n_frames, n_markers = positions.shape[:2]
    present = visible(positions)
    mate_index = mates(stats, 3)
    near_index = nearest(stats, 1)
    out = np.array(positions, dtype=np.float64, copy=True)
    busy = np.zeros(n_frames, dtype=bool)
    truth: list[InjectedSwap] = []
    low, high = max(1, round(min_s * fps)), max(1, round(max_s * fps))
    for _ in range(max_tries):
        if len(truth) == count:
            break
        a = int(rng.integers(n_markers))
        partners = mate_index[a][mate_index[a] >= 0]
        if partners.size == 0:
            partners = near_index[a][near_index[a] >= 0]
        if partners.size == 0:
            continue
        b = int(rng.choice(partners))
        if any({a, b} & {t.a, t.b} for t in truth):
            continue
        length = int(rng.integers(low, high + 1))
        if n_frames - 2 * margin - length <= 0:
            continue
        start = int(rng.integers(margin, n_frames - margin - length + 1))
        end = start + length - 1
        window = slice(max(start - margin, 0), end + margin + 1)
        if busy[window].any() or not present[start - 1 : end + 2, [a, b]].all():
            continue
        out[start : end + 1, [a, b]] = out[start : end + 1, [b, a]]
        busy[start : end + 1] = True
        truth.append(InjectedSwap(a, b, start, end))
    if len(truth) < count:
        raise InputError(f"Expected room for {count} swaps, placed {len(truth)}")
    return out, sorted(truth, key=lambda t: t.start)
