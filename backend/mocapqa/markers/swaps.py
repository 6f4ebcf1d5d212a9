"""Label swaps: two labels exchanging trajectories over an interval, found from the rigid
distances of the markers' mates, and their repair.

Conventions
-----------
* A marker's **misfit** at a frame is the mean, over its visible mates
  (:func:`mocapqa.markers.segments.mates`) without the largest when three or more are
  visible, of ``|d(t) − median| / tolerance`` where ``d`` is the distance to the mate,
  ``median`` its usual value and ``tolerance`` half the pair's spread, at least
  ``tolerance_floor`` (:func:`tolerances`). A marker is **suspect** where its misfit exceeds
  ``swap_misfit``.
* Candidate pairs are each marker's mates and its ``neighbours`` nearest markers; a pair is
  tested when one of its markers is suspect somewhere (and has a mate other than its
  partner), or when it shows the crossing cue twice.
* The **exchange test** measures each marker of the pair against its mates other than its
  partner (their distance does not change in an exchange), where it is and at the partner's
  position. A frame is **explained** when both markers are visible, the larger misfit is
  above ``swap_misfit`` and the larger exchanged one below it, and the summed misfit falls
  below ``swap_gain`` of its value; **contradicted** when the larger misfit is below
  ``swap_misfit`` and the larger exchanged one above; **neither** when both are above.
* A swap is a run of frames without contradiction that holds explained frames, trimmed to
  explained frames at both ends (frames where the test cannot tell, a marker missing or the
  two close together, are bridged), or the stretch between two successive crossings of a pair.
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
* **Confidence** in [0, 1]: the share of explained frames among the explained, contradicted
  and neither frames (neither counted up to three frames either side: a tracking glitch is
  not a clean exchange), times ``1 − after / before`` of the median misfits over the
  explained frames; raised by a third of the remainder per boundary showing the crossing
  cue; times one minus the share of contradicted frames. Swaps under ``swap_report`` are
  not listed; of swaps overlapping in time whose markers are the same or mates, the one with
  the larger ``confidence × frames`` is kept.
* Frames are 0-based, ends inclusive. Repair exchanges the two labels' samples (positions and
  anything else per sample) over the interval: :func:`repair_swaps`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, column_runs
from mocapqa.errors import InputError, OptionError
from mocapqa.markers.params import MarkerParams, unit_scale
from mocapqa.markers.segments import PairStats, mates, nearest
from mocapqa.markers.take import visible

__all__ = [
    "APPLY_RULES",
    "Swap",
    "candidate_pairs",
    "crossings",
    "find_swaps",
    "labels_held",
    "misfits",
    "repair_swaps",
    "select_swaps",
    "swapped_mask",
    "swaps_and_misfits",
    "tolerances",
]

_CONTEXT = 3
"""Frames either side of a swap whose misfits count toward its confidence."""
APPLY_RULES = ("confident", "all", "none")
"""Which swaps a repair applies: those at or above ``swap_confidence``, all, or none."""


@dataclass(frozen=True, slots=True)
class Swap:
    """Two labels exchanging trajectories over a run of frames.

    Parameters
    ----------
    markers : tuple of str
        The two labels (A, B), A before B in the take's order.
    indices : tuple of int
        Their indices.
    start, end : int
        First and last swapped frame, 0-based, inclusive.
    confidence : float
        0–1.
    misfit : float
        Median misfit of the two markers over the interval before the exchange (tolerances).
    repaired_misfit : float
        The same after the exchange.
    crossing : tuple of bool
        Whether the crossing cue holds at the start and at the release.
    severity : {"warning", "error"}
        Error at or above ``swap_confidence``.
    """

    markers: tuple[str, str]
    indices: tuple[int, int]
    start: int
    end: int
    confidence: float
    misfit: float
    repaired_misfit: float
    crossing: tuple[bool, bool]
    severity: str


def tolerances(stats: PairStats, length_unit: str, params: MarkerParams) -> FloatArray:
    """``(M, M)`` tolerance of every pair's distance: half its spread, at least
    ``tolerance_floor`` (mm, in take units); inf for pairs never seen together."""
    floor = params.tolerance_floor * unit_scale(length_unit)
    half = np.where(np.isfinite(stats.spread), stats.spread / 2.0, np.inf)
    tolerance: FloatArray = np.maximum(half, floor)
    return tolerance


def _trimmed_mean_last(values: FloatArray) -> FloatArray:
    """Mean along the last axis of values ≥ 0 without the largest (when 3 or more are
    finite), NaN left out (NaN when all are): one mate that moved on its own does not make a
    misfit."""
    finite = np.isfinite(values)
    counts = finite.sum(axis=-1)
    filled = np.where(finite, values, 0.0)
    trimmed = counts >= 3
    total = filled.sum(axis=-1) - np.where(trimmed, filled.max(axis=-1, initial=0.0), 0.0)
    kept = counts - trimmed
    with np.errstate(invalid="ignore", divide="ignore"):
        mean: FloatArray = np.where(counts > 0, total / np.maximum(kept, 1), np.nan)
    return mean


def _distances(positions: FloatArray, first: IntArray, second: IntArray) -> FloatArray:
    """``(F, *first.shape)`` distances between markers ``first`` and ``second``."""
    diff = positions[:, first] - positions[:, second]
    distance: FloatArray = np.sqrt(np.einsum("f...k,f...k->f...", diff, diff))
    return distance


@dataclass(frozen=True, slots=True)
class _Residuals:
    """Residuals of every mate pair, once per unordered pair.

    ``values`` ``(F, Q + 1)``: ``|d − median| / tolerance`` per pair, then a NaN column;
    ``column`` ``(M, K)``: the column of each marker's k-th mate (Q, the NaN column, where
    the slot is empty).
    """

    values: FloatArray
    column: IntArray


def _residuals(
    positions: FloatArray, mate_index: IntArray, stats: PairStats, tolerance: FloatArray
) -> _Residuals:
    n_markers, n_slots = mate_index.shape
    valid = mate_index >= 0
    rows = np.broadcast_to(np.arange(n_markers)[:, None], (n_markers, n_slots))
    keys = np.minimum(rows, mate_index) * n_markers + np.maximum(rows, mate_index)
    unique, inverse = np.unique(keys[valid], return_inverse=True)
    column = np.full((n_markers, n_slots), unique.size, dtype=np.intp)
    column[valid] = inverse
    i, j = unique // n_markers, unique % n_markers
    values = np.full((positions.shape[0], unique.size + 1), np.nan)
    values[:, :-1] = np.abs(_distances(positions, i, j) - stats.median[i, j]) / tolerance[i, j]
    return _Residuals(values, column)


def misfits(
    positions: FloatArray, mate_index: IntArray, stats: PairStats, tolerance: FloatArray
) -> FloatArray:
    """Every marker's misfit at every frame.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
    mate_index : ndarray of int, shape (M, K)
        -1 padded (:func:`mocapqa.markers.segments.mates`).
    stats : PairStats
    tolerance : ndarray, shape (M, M)
        Take units.

    Returns
    -------
    ndarray, shape (F, M)
        Tolerances; NaN where the marker or all its mates are missing, or it has no mates.
    """
    table = _residuals(positions, mate_index, stats, tolerance)
    return _trimmed_mean_last(table.values[:, table.column])


def candidate_pairs(mate_index: IntArray, near_index: IntArray) -> IntArray:
    """Unique marker pairs ``(P, 2)``, A < B: each marker with its mates and nearest markers."""
    partners = np.concatenate([mate_index, near_index], axis=1)
    first = np.repeat(np.arange(partners.shape[0]), partners.shape[1])
    second = partners.ravel()
    keep = (second >= 0) & (second != first)
    pairs = np.sort(np.stack([first[keep], second[keep]], axis=1), axis=1)
    unique: IntArray = np.unique(pairs, axis=0).astype(np.intp).reshape(-1, 2)
    return unique


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


def _pair_misfit(
    positions: FloatArray,
    table: _Residuals,
    mover: IntArray,
    other: IntArray,
    mate_index: IntArray,
    stats: PairStats,
    tolerance: FloatArray,
    exchanged: bool,
) -> FloatArray:
    """(F, P) misfit of each pair's marker ``mover`` against its mates other than ``other``
    (their distance does not change in an exchange), at its own positions or, when
    ``exchanged``, at ``other``'s."""
    k_mates = mate_index[mover]  # (P, K)
    valid = (k_mates >= 0) & (k_mates != other[:, None])
    if not exchanged:
        column = np.where(valid, table.column[mover], table.values.shape[1] - 1)
        return _trimmed_mean_last(table.values[:, column])
    safe = np.where(valid, k_mates, 0)
    rows = mover[:, None]
    usual = np.where(valid, stats.median[rows, safe], np.nan)
    distance = _distances(positions, np.broadcast_to(other[:, None], safe.shape), safe)
    return _trimmed_mean_last(np.abs(distance - usual) / tolerance[rows, safe])


@dataclass(frozen=True, slots=True)
class _Evidence:
    """Per-frame evidence of the tested pairs, ``(F, P)`` each."""

    explained: BoolArray
    contradicted: BoolArray
    neither: BoolArray
    before: FloatArray
    after: FloatArray
    crossed: BoolArray


def _evidence(
    positions: FloatArray,
    table: _Residuals,
    a: IntArray,
    b: IntArray,
    mate_index: IntArray,
    stats: PairStats,
    tolerance: FloatArray,
    crossed: BoolArray,
    params: MarkerParams,
) -> _Evidence:
    args = (mate_index, stats, tolerance)
    before_a = _pair_misfit(positions, table, a, b, *args, exchanged=False)
    before_b = _pair_misfit(positions, table, b, a, *args, exchanged=False)
    after_a = _pair_misfit(positions, table, a, b, *args, exchanged=True)
    after_b = _pair_misfit(positions, table, b, a, *args, exchanged=True)
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
    return _Evidence(explained, contradicted, neither, before, after, crossed)


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


def _intervals(evidence: _Evidence) -> list[tuple[int, int, int]]:
    """Candidate intervals ``(column, start, end)``: runs without contradiction trimmed to
    explained frames, and the stretches between successive crossings of one pair."""
    found: list[tuple[int, int, int]] = []
    columns, starts, ends = column_runs(~evidence.contradicted)
    for column, start, end in zip(columns, starts, ends, strict=True):
        hits = np.flatnonzero(evidence.explained[start : end + 1, column])
        if hits.size:
            found.append((int(column), int(start + hits[0]), int(start + hits[-1])))
    frames, columns = np.nonzero(evidence.crossed)
    order = np.lexsort((frames, columns))
    frames, columns = frames[order], columns[order]
    same = columns[1:] == columns[:-1]
    for i in np.flatnonzero(same):
        found.append((int(columns[i]), int(frames[i]), int(frames[i + 1]) - 1))
    return found


def _confidence(evidence: _Evidence, column: int, start: int, end: int) -> tuple[float, ...]:
    """``(confidence, misfit before, misfit after, crossed at start, crossed at release)``."""
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


def find_swaps(
    positions: FloatArray,
    names: Sequence[str],
    stats: PairStats,
    length_unit: str,
    params: MarkerParams | None = None,
) -> list[Swap]:
    """Swaps between neighbouring markers.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    names : sequence of str
    stats : PairStats
        Of this take (:func:`mocapqa.markers.segments.pair_stats`).
    length_unit : str
    params : MarkerParams, optional

    Returns
    -------
    list of Swap
        With confidence at least ``swap_report``, by start frame, then markers.
    """
    return swaps_and_misfits(positions, names, stats, length_unit, params)[0]


def swaps_and_misfits(
    positions: FloatArray,
    names: Sequence[str],
    stats: PairStats,
    length_unit: str,
    params: MarkerParams | None = None,
) -> tuple[list[Swap], FloatArray]:
    """:func:`find_swaps` and the :func:`misfits` it measures them with, ``(F, M)``."""
    p = params or MarkerParams()
    mate_index = mates(stats, p.max_mates, p.mate_score)
    tolerance = tolerances(stats, length_unit, p)
    with np.errstate(invalid="ignore"):
        table = _residuals(positions, mate_index, stats, tolerance)
        misfit = _trimmed_mean_last(table.values[:, table.column])
        suspect = misfit > p.swap_misfit  # (F, M)
    pairs = candidate_pairs(mate_index, nearest(stats, p.neighbours))
    if pairs.size == 0:
        return [], misfit
    a, b = pairs[:, 0], pairs[:, 1]
    # A marker of a pair is testable when it has a mate other than its partner.
    valid = mate_index >= 0
    others = valid.sum(axis=1)
    usable_a = others[a] - (mate_index[a] == b[:, None]).sum(axis=1) > 0
    usable_b = others[b] - (mate_index[b] == a[:, None]).sum(axis=1) > 0
    crossed = crossings(positions, a, b, stats.median[a, b], p.swap_cross)
    tested = ((suspect[:, a] & usable_a) | (suspect[:, b] & usable_b)).any(axis=0) | (
        crossed.sum(axis=0) >= 2
    )
    if not tested.any():
        return [], misfit
    a, b = a[tested], b[tested]
    evidence = _evidence(
        positions, table, a, b, mate_index, stats, tolerance, crossed[:, tested], p
    )
    scored: list[tuple[float, Swap]] = []
    for column, start, end in _intervals(evidence):
        confidence, level_before, level_after, at_start, at_end = _confidence(
            evidence, column, start, end
        )
        ia, ib = int(a[column]), int(b[column])
        if confidence < p.swap_report or any(
            labels_held(positions, ia, ib, float(stats.median[ia, ib]), frame, p)
            for frame in (start, end + 1)
        ):
            continue
        severity = "error" if confidence >= p.swap_confidence else "warning"
        swap = Swap(
            (names[ia], names[ib]), (ia, ib), start, end, round(float(confidence), 4),
            level_before, level_after, (bool(at_start), bool(at_end)), severity,
        )  # fmt: skip
        scored.append((confidence * (end - start + 1), swap))
    n_markers = mate_index.shape[0]
    related = np.eye(n_markers, dtype=bool)
    rows = np.repeat(np.arange(n_markers), mate_index.shape[1])
    partners = mate_index.ravel()
    related[rows[partners >= 0], partners[partners >= 0]] = True
    return _resolve(scored, related | related.T), misfit


def _resolve(scored: list[tuple[float, Swap]], related: BoolArray) -> list[Swap]:
    """Keep, of swaps overlapping in time that share a marker or ride on one segment (a swap
    moves its markers' mates' distances too, so an exchange of two mates can look half
    right), the one with more evidence.

    ``related`` is the ``(M, M)`` mate relation, symmetric, True on the diagonal.
    """
    kept: list[Swap] = []
    for _, swap in sorted(scored, key=lambda item: -item[0]):
        clash = any(
            related[np.ix_(swap.indices, other.indices)].any()
            and swap.start <= other.end
            and other.start <= swap.end
            for other in kept
        )
        if not clash:
            kept.append(swap)
    return sorted(kept, key=lambda s: (s.start, s.indices))


def select_swaps(
    swaps: Sequence[Swap],
    apply: Literal["confident", "all", "none"] | str,
    params: MarkerParams | None = None,
) -> list[Swap]:
    """The swaps a repair applies under ``apply`` (:data:`APPLY_RULES`).

    Raises
    ------
    OptionError
        If ``apply`` is not one of :data:`APPLY_RULES`.
    """
    p = params or MarkerParams()
    if apply not in APPLY_RULES:
        raise OptionError("apply", f"Expected one of {', '.join(APPLY_RULES)}, got {apply!r}")
    if apply == "none":
        return []
    if apply == "all":
        return list(swaps)
    return [s for s in swaps if s.confidence >= p.swap_confidence]


def repair_swaps(samples: FloatArray, swaps: Sequence[Swap]) -> FloatArray:
    """A copy of ``samples`` with each swap's two labels exchanged over its interval.

    Parameters
    ----------
    samples : ndarray, shape (F, M, ...)
        Positions ``(F, M, 3)``, residuals ``(F, M)`` or any per-sample array.
    swaps : sequence of Swap
        Applied in order; they should not share a marker over overlapping frames.

    Returns
    -------
    ndarray
        Same shape and dtype; ``samples`` is not modified.

    Raises
    ------
    InputError
        If a swap lies outside the take.
    """
    out = np.array(samples, copy=True)
    n_frames, n_markers = out.shape[:2]
    for swap in swaps:
        a, b = swap.indices
        if not (0 <= swap.start <= swap.end < n_frames and 0 <= a < n_markers
                and 0 <= b < n_markers):  # fmt: skip
            raise InputError(
                f"Expected a swap inside {n_frames} frames and {n_markers} markers, got "
                f"markers {a}, {b} over frames {swap.start}–{swap.end}"
            )
        window = slice(swap.start, swap.end + 1)
        out[window, [a, b]] = out[window, [b, a]]
    return out


def swapped_mask(shape: tuple[int, int], swaps: Sequence[Swap]) -> BoolArray:
    """``(F, M)`` mask of the samples the swaps exchange."""
    mask = np.zeros(shape, dtype=bool)
    for swap in swaps:
        mask[swap.start : swap.end + 1, list(swap.indices)] = True
    return mask
