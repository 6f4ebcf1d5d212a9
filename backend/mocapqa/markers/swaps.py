"""Label swaps: two labels exchanging trajectories over an interval, found from the rigid
distances of the markers' mates.

Conventions
-----------
* A marker's **misfit** (:func:`mocapqa.markers.misfits.misfits`) is its mean distance error
  against its rigid mates, in tolerances. A marker is **suspect** where its misfit exceeds
  ``swap_misfit``.
* Candidate pairs are each marker's mates and its ``neighbours`` nearest markers; a pair is
  tested when one of its markers is suspect somewhere (and has a mate other than its
  partner), or when it shows the crossing cue twice.
* A tested pair's frames are explained, contradicted or neither by the exchange test, and its
  candidate intervals are scored and checked at their boundaries
  (:mod:`mocapqa.markers.swap_evidence`). A swap is a candidate interval of confidence at least
  ``swap_report`` whose boundaries do not hold the labels apart; of swaps overlapping in time
  whose markers are the same or mates, the one with the larger ``confidence × frames`` is
  kept.
* Frames are 0-based, ends inclusive. Repair exchanges the two labels' samples (positions and
  anything else per sample) over the interval: :func:`mocapqa.markers.swap_repair.repair_swaps`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.markers.misfits import residual_table, tolerances
from mocapqa.markers.params import MarkerParams
from mocapqa.markers.segments import PairStats, mates, nearest
from mocapqa.markers.swap_evidence import (
    ExchangeEvidence,
    crossing_intervals,
    crossings,
    exchange_evidence,
    interval_confidence,
    labels_held,
    run_intervals,
)

__all__ = ["Swap", "candidate_pairs", "find_swaps", "swaps_and_misfits"]


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


def candidate_pairs(mate_index: IntArray, near_index: IntArray) -> IntArray:
    """Unique marker pairs ``(P, 2)``, A < B: each marker with its mates and nearest markers."""
    partners = np.concatenate([mate_index, near_index], axis=1)
    first = np.repeat(np.arange(partners.shape[0]), partners.shape[1])
    second = partners.ravel()
    keep = (second >= 0) & (second != first)
    pairs = np.sort(np.stack([first[keep], second[keep]], axis=1), axis=1)
    unique: IntArray = np.unique(pairs, axis=0).astype(np.intp).reshape(-1, 2)
    return unique


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
    """:func:`find_swaps` and the misfits it measures them with, ``(F, M)`` tolerances
    (:func:`mocapqa.markers.misfits.misfits`)."""
    p = params or MarkerParams()
    mate_index = mates(stats, p.max_mates, p.mate_score)
    tolerance = tolerances(stats, length_unit, p)
    with np.errstate(invalid="ignore"):
        table = residual_table(positions, mate_index, stats, tolerance)
        misfit = table.misfits()
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
    blocks = _blocks(a.size, positions.shape[0])
    crossed = np.concatenate(
        [crossings(positions, a[s], b[s], stats.median[a[s], b[s]], p.swap_cross) for s in blocks],
        axis=1,
    )
    tested = ((suspect[:, a] & usable_a) | (suspect[:, b] & usable_b)).any(axis=0) | (
        crossed.sum(axis=0) >= 2
    )
    if not tested.any():
        return [], misfit
    a, b, crossed = a[tested], b[tested], crossed[:, tested]
    # Pairs are tested a block at a time; the runs of every block come before the crossing
    # stretches, in pair order, as one call over all pairs would give them.
    runs: list[tuple[float, Swap]] = []
    stretches: list[tuple[float, Swap]] = []
    for block in _blocks(a.size, positions.shape[0]):
        evidence = exchange_evidence(
            positions, table, a[block], b[block], mate_index, stats, tolerance,
            crossed[:, block], p,
        )  # fmt: skip
        pair = (a[block], b[block])
        runs += _scored(positions, names, stats, p, evidence, pair, run_intervals(evidence))
        found = crossing_intervals(evidence.crossed)
        stretches += _scored(positions, names, stats, p, evidence, pair, found)
    n_markers = mate_index.shape[0]
    related = np.eye(n_markers, dtype=bool)
    rows = np.repeat(np.arange(n_markers), mate_index.shape[1])
    partners = mate_index.ravel()
    related[rows[partners >= 0], partners[partners >= 0]] = True
    return _resolve(runs + stretches, related | related.T), misfit


_BLOCK_CELLS = 1 << 17
"""Frames × pairs tested at once: bounds the memory of the exchange test on a take with many
markers (600 frames × 1,000 random markers: 95 MB peak). Smaller blocks cost the usual take
time in per-block overhead: 2**15 made the check of a 10,000-frame, 60-marker take 1.8× slower;
2**17 keeps it at the speed of testing every pair at once (0.96×, CPU time, best of four)."""


def _blocks(n_pairs: int, n_frames: int) -> list[slice]:
    """Consecutive slices of ``n_pairs`` pairs, each of at most ``_BLOCK_CELLS`` frames × pairs
    (at least one pair)."""
    width = max(1, _BLOCK_CELLS // max(n_frames, 1))
    return [slice(first, first + width) for first in range(0, max(n_pairs, 1), width)]


def _scored(
    positions: FloatArray,
    names: Sequence[str],
    stats: PairStats,
    params: MarkerParams,
    evidence: ExchangeEvidence,
    pair: tuple[IntArray, IntArray],
    intervals: list[tuple[int, int, int]],
) -> list[tuple[float, Swap]]:
    """The swaps of candidate ``intervals`` ``(column, start, end)`` of pairs ``pair`` (their
    markers A and B, ``(P,)`` each, one per column of ``evidence``) that reach
    ``swap_report`` and whose boundaries do not hold the labels apart, each with its
    ``confidence × frames``, in the order of ``intervals``."""
    scored: list[tuple[float, Swap]] = []
    for column, start, end in intervals:
        confidence, level_before, level_after, at_start, at_end = interval_confidence(
            evidence, column, start, end
        )
        ia, ib = int(pair[0][column]), int(pair[1][column])
        if confidence < params.swap_report or any(
            labels_held(positions, ia, ib, float(stats.median[ia, ib]), frame, params)
            for frame in (start, end + 1)
        ):
            continue
        severity = "error" if confidence >= params.swap_confidence else "warning"
        swap = Swap(
            (names[ia], names[ib]), (ia, ib), start, end, round(float(confidence), 4),
            level_before, level_after, (bool(at_start), bool(at_end)), severity,
        )  # fmt: skip
        scored.append((confidence * (end - start + 1), swap))
    return scored


def _resolve(scored: list[tuple[float, Swap]], related: BoolArray) -> list[Swap]:
    """Keep, of swaps overlapping in time that share a marker or ride on one segment (a swap
    moves its markers' mates' distances too, so an exchange of two mates can look half
    right), the one with more evidence.

    ``related`` is the ``(M, M)`` mate relation, symmetric, True on the diagonal.
    """
    ranked = [swap for _, swap in sorted(scored, key=lambda item: -item[0])]
    kept: list[Swap] = []
    # The kept swaps' markers and frames, filled as they are kept.
    first = np.empty(len(ranked), dtype=np.intp)
    second = np.empty(len(ranked), dtype=np.intp)
    starts = np.empty(len(ranked), dtype=np.intp)
    ends = np.empty(len(ranked), dtype=np.intp)
    for swap in ranked:
        n_kept = len(kept)
        overlapping = (starts[:n_kept] <= swap.end) & (swap.start <= ends[:n_kept])
        if overlapping.any():
            near = related[swap.indices[0]] | related[swap.indices[1]]  # (M,)
            clash = overlapping & (near[first[:n_kept]] | near[second[:n_kept]])
            if clash.any():
                continue
        first[n_kept], second[n_kept] = swap.indices
        starts[n_kept], ends[n_kept] = swap.start, swap.end
        kept.append(swap)
    return sorted(kept, key=lambda s: (s.start, s.indices))
