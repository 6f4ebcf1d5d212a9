"""The exchange test of marker pairs: per-frame evidence that two labels exchanged
trajectories, the crossing cue, the boundary test, and the candidate intervals with their
confidence (:mod:`mocapqa.markers.swaps` finds the swaps from them).

Conventions
-----------
* The **exchange test** measures each marker of the pair against its mates other than its
  partner (their distance does not change in an exchange), where it is and at the partner's
  position (:func:`mocapqa.markers.misfits.pair_misfit`). A frame is **explained** when both
  markers are visible, the larger misfit is above ``swap_misfit`` and the larger exchanged
  one below it, and the summed misfit falls below ``swap_gain`` of its value;
  **contradicted** when the larger misfit is below ``swap_misfit`` and the larger exchanged
  one above; **neither** when both are above.
* A candidate interval is a run of frames without contradiction that holds explained frames,
  trimmed to explained frames at both ends (frames where the test cannot tell, a marker
  missing or the two close together, are bridged), or the stretch between two successive
  crossings of a pair.
* **Crossing cue** (:func:`crossings`): at a swap's first frame ``s`` each label jumps to the
  other's previous position, ``|A(s) − B(s−1)| + |B(s) − A(s−1)| < swap_cross · (|A(s) −
  A(s−1)| + |B(s) − B(s−1)|)``, and back at ``end + 1``.
* **Boundary test** (:func:`labels_held`): a swap is rejected when, at its first frame or
  at its release, both markers are seen over the ``swap_window`` frames either side and each
  label keeps its own trajectory there: each label's position, predicted at constant
  velocity from its two previous ones, is nearer its own prediction than the other's by more
  than ``swap_held`` times the pair's median distance (summed over the two labels), at every
  one of those frames: two labels well apart cannot exchange without a jump. A boundary at
  a gap, at the take's edge or where the two markers are close together does not reject.
* **Confidence** in [0, 1] (:func:`interval_confidence`): the share of explained frames among
  the explained, contradicted and neither frames (neither counted up to three frames either
  side: a tracking glitch is not a clean exchange), times ``1 − after / before`` of the
  median misfits over the explained frames; raised by a third of the remainder per boundary
  showing the crossing cue; times one minus the share of contradicted frames.
* Frames are 0-based, ends inclusive.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, column_runs
from mocapqa.markers.misfits import ResidualTable, pair_misfit
from mocapqa.markers.params import MarkerParams
from mocapqa.markers.segments import PairStats
from mocapqa.markers.take import visible

__all__ = [
    "ExchangeEvidence",
    "candidate_intervals",
    "crossing_intervals",
    "crossings",
    "exchange_evidence",
    "interval_confidence",
    "labels_held",
    "run_intervals",
]

_CONTEXT = 3
"""Frames either side of a swap whose misfits count toward its confidence."""


def crossings(
    positions: FloatArray, a: IntArray, b: IntArray, usual: FloatArray, cross: float
) -> BoolArray:
    """``(F, P)``: where each pair's labels take each other's previous positions.

    At frame t (≥ 1), with both markers visible at t − 1 and t:
    ``|A(t) − B(t−1)| + |B(t) − A(t−1)| < cross · (|A(t) − A(t−1)| + |B(t) − B(t−1)|)``.
    By the triangle inequality this needs the two steps to add up to more than
    ``2 δ / (1 + cross)`` for a separation δ before the jump; only frames whose steps add up
    to a quarter of that for the pair's ``usual`` (median) distance are tested, so two
    markers passing within a quarter of their usual distance of each other are not.
    Frame 0 is False.
    """
    n_frames = positions.shape[0]
    out = np.zeros((n_frames, a.size), dtype=bool)
    if n_frames < 2 or a.size == 0:
        return out
    step = np.full(positions.shape[:2], np.nan)
    delta = positions[1:] - positions[:-1]
    step[1:] = np.sqrt(np.einsum("fmk,fmk->fm", delta, delta))
    along = step[:, a] + step[:, b]
    with np.errstate(invalid="ignore"):
        frames, pairs = np.nonzero(along * (1.0 + cross) > 0.5 * usual)
    ia, ib = a[pairs], b[pairs]

    def length(v: FloatArray) -> FloatArray:
        result: FloatArray = np.sqrt(np.einsum("nk,nk->n", v, v))
        return result

    across = length(positions[frames, ia] - positions[frames - 1, ib]) + length(
        positions[frames, ib] - positions[frames - 1, ia]
    )
    with np.errstate(invalid="ignore"):
        out[frames, pairs] = across < cross * along[frames, pairs]
    return out


@dataclass(frozen=True, slots=True)
class ExchangeEvidence:
    """Per-frame evidence of the tested pairs, ``(F, P)`` each.

    Parameters
    ----------
    explained, contradicted, neither : ndarray of bool, shape (F, P)
        Frames an exchange explains, contradicts, or where neither labelling fits.
    before, after : ndarray, shape (F, P)
        The larger misfit of the pair's two markers as labelled and exchanged, tolerances.
    crossed : ndarray of bool, shape (F, P)
        Where the crossing cue holds (:func:`crossings`).
    """

    explained: BoolArray
    contradicted: BoolArray
    neither: BoolArray
    before: FloatArray
    after: FloatArray
    crossed: BoolArray


def exchange_evidence(
    positions: FloatArray,
    table: ResidualTable,
    a: IntArray,
    b: IntArray,
    mate_index: IntArray,
    stats: PairStats,
    tolerance: FloatArray,
    crossed: BoolArray,
    params: MarkerParams,
) -> ExchangeEvidence:
    """The exchange test of pairs ``(a, b)`` at every frame.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    table : ResidualTable
        Of ``positions`` (:func:`mocapqa.markers.misfits.residual_table`).
    a, b : ndarray of int, shape (P,)
        The pairs' markers.
    mate_index : ndarray of int, shape (M, K)
    stats : PairStats
    tolerance : ndarray, shape (M, M)
        Take units.
    crossed : ndarray of bool, shape (F, P)
        The pairs' crossing cue (:func:`crossings`).
    params : MarkerParams

    Returns
    -------
    ExchangeEvidence
    """
    args = (mate_index, stats, tolerance)
    before_a = pair_misfit(positions, table, a, b, *args, exchanged=False)
    before_b = pair_misfit(positions, table, b, a, *args, exchanged=False)
    after_a = pair_misfit(positions, table, a, b, *args, exchanged=True)
    after_b = pair_misfit(positions, table, b, a, *args, exchanged=True)
    before = np.fmax(before_a, before_b)
    after = np.fmax(after_a, after_b)
    present = visible(positions)
    known = present[:, a] & present[:, b] & np.isfinite(before) & np.isfinite(after)
    with np.errstate(invalid="ignore"):
        total_before = np.where(np.isnan(before_a), 0.0, before_a) + np.where(
            np.isnan(before_b), 0.0, before_b
        )
        total_after = np.where(np.isnan(after_a), 0.0, after_a) + np.where(
            np.isnan(after_b), 0.0, after_b
        )
        explained = (
            known
            & (before > params.swap_misfit)
            & (after < params.swap_misfit)
            & (total_after < params.swap_gain * total_before)
        )
        contradicted = known & (before < params.swap_misfit) & (after > params.swap_misfit)
        neither = known & (before > params.swap_misfit) & (after > params.swap_misfit)
    return ExchangeEvidence(explained, contradicted, neither, before, after, crossed)


def labels_held(
    positions: FloatArray, a: int, b: int, usual: float, frame: int, params: MarkerParams
) -> bool:
    """Whether labels ``a`` and ``b`` keep their own trajectories around ``frame``.

    Over the frames ``frame − swap_window − 2`` to ``frame + swap_window``, both markers
    must be visible at the first two and the last; for each frame ``v`` where both are
    visible after those two, each label's position is predicted at constant velocity from
    the two visible frames before it (a gap inside is bridged), ``P(v)``, and the exchanged
    predictions must miss by more than the kept ones, ``|A(v) − P_B(v)| + |B(v) − P_A(v)| −
    |A(v) − P_A(v)| − |B(v) − P_B(v)| > swap_held · usual``: an exchange of the labels
    anywhere there would need a jump that is not seen, however fast the two move. False near
    the take's edges, where a marker is missing at the window's ends, where the two are
    close together or a label jumps.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    a, b : int
        Marker indices.
    usual : float
        The pair's median distance, take units.
    frame : int
        The first frame after the boundary (a swap's start, or its end + 1), 0-based.
    params : MarkerParams

    Returns
    -------
    bool
    """
    first, last = frame - params.swap_window - 2, frame + params.swap_window
    if first < 0 or last >= positions.shape[0] or not np.isfinite(usual):
        return False
    window = positions[first : last + 1][:, [a, b]]  # (W, 2, 3)
    seen = np.flatnonzero(visible(window).all(axis=1))
    if seen.size < 3 or seen[0] != 0 or seen[1] != 1 or seen[-1] != window.shape[0] - 1:
        return False
    older, was, now = seen[:-2], seen[1:-1], seen[2:]
    ratio = ((now - was) / (was - older))[:, None, None]
    predicted = window[was] + (window[was] - window[older]) * ratio  # (T, 2, 3)
    kept = np.linalg.norm(window[now] - predicted, axis=2).sum(axis=1)
    exchanged = np.linalg.norm(window[now] - predicted[:, ::-1], axis=2).sum(axis=1)
    return bool((exchanged - kept > params.swap_held * usual).all())


def candidate_intervals(evidence: ExchangeEvidence) -> list[tuple[int, int, int]]:
    """Candidate intervals ``(column, start, end)``, frames 0-based and ends inclusive: runs
    without contradiction trimmed to explained frames (:func:`run_intervals`), then the
    stretches between successive crossings of one pair (:func:`crossing_intervals`)."""
    return run_intervals(evidence) + crossing_intervals(evidence.crossed)


def run_intervals(evidence: ExchangeEvidence) -> list[tuple[int, int, int]]:
    """Runs without contradiction trimmed to explained frames, ``(column, start, end)`` by
    column then start, frames 0-based and ends inclusive."""
    found: list[tuple[int, int, int]] = []
    columns, starts, ends = column_runs(~evidence.contradicted)
    for column, start, end in zip(columns, starts, ends, strict=True):
        hits = np.flatnonzero(evidence.explained[start : end + 1, column])
        if hits.size:
            found.append((int(column), int(start + hits[0]), int(start + hits[-1])))
    return found


def crossing_intervals(crossed: BoolArray) -> list[tuple[int, int, int]]:
    """The stretches between successive crossings of one pair, ``(column, start, end)`` by
    column then start, frames 0-based and ends inclusive.

    Parameters
    ----------
    crossed : ndarray of bool, shape (F, P)
        The pairs' crossing cue (:func:`crossings`).

    Returns
    -------
    list of tuple of int
    """
    frames, columns = np.nonzero(crossed)
    order = np.lexsort((frames, columns))
    frames, columns = frames[order], columns[order]
    same = columns[1:] == columns[:-1]
    return [(int(columns[i]), int(frames[i]), int(frames[i + 1]) - 1) for i in np.flatnonzero(same)]


def interval_confidence(
    evidence: ExchangeEvidence, column: int, start: int, end: int
) -> tuple[float, ...]:
    """``(confidence, misfit before, misfit after, crossed at start, crossed at release)`` of
    the interval ``start``–``end`` (0-based, inclusive) of pair ``column``; misfits in
    tolerances, the crossings 0.0 or 1.0."""
    window = slice(start, end + 1)
    hit = evidence.explained[window, column]
    n_hit = int(hit.sum())
    n_against = int(evidence.contradicted[window, column].sum())
    # Frames where neither labelling fits, in the interval or just around it: a tracking
    # glitch rather than a clean exchange.
    around = slice(max(start - _CONTEXT, 0), end + 1 + _CONTEXT)
    n_neither = int(evidence.neither[around, column].sum())
    if n_hit:
        level_before = float(np.median(evidence.before[window, column][hit]))
        level_after = float(np.median(evidence.after[window, column][hit]))
        margin = 1.0 - min(level_after / max(level_before, 1e-12), 1.0)
        distance = n_hit / (n_hit + n_against + n_neither) * margin
    else:
        level_before = level_after = float("nan")
        distance = 0.0
    n_frames = evidence.crossed.shape[0]
    at_start = bool(evidence.crossed[start, column])
    at_end = bool(end + 1 < n_frames and evidence.crossed[end + 1, column])
    confidence = distance + (1.0 - distance) * (at_start + at_end) / 3.0
    length = end - start + 1
    confidence *= 1.0 - n_against / length
    return confidence, level_before, level_after, float(at_start), float(at_end)
