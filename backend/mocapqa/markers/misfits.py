"""Misfits of markers against their rigid mates: how far each marker's distances to its mates
stray from their usual values, in tolerances.

Conventions
-----------
* A marker's **misfit** at a frame is the mean, over its visible mates
  (:func:`mocapqa.markers.segments.mates`) without the largest when three or more are
  visible, of ``|d(t) − median| / tolerance`` where ``d`` is the distance to the mate,
  ``median`` its usual value and ``tolerance`` half the pair's spread, at least
  ``tolerance_floor`` (:func:`tolerances`).
* A pair's **exchanged** misfit (:func:`pair_misfit`) measures one marker of the pair at the
  other's position, against its mates other than its partner: what the misfit would be were
  the two labels exchanged. Swaps (:mod:`mocapqa.markers.swaps`) and spikes
  (:mod:`mocapqa.markers.spikes`) are found from these.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.markers.params import MarkerParams, unit_scale
from mocapqa.markers.segments import PairStats

__all__ = ["ResidualTable", "misfits", "pair_misfit", "residual_table", "tolerances"]


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
class ResidualTable:
    """Residuals of every mate pair, once per unordered pair.

    Parameters
    ----------
    values : ndarray, shape (F, Q + 1)
        ``|d − median| / tolerance`` per pair (tolerances), then a NaN column.
    column : ndarray of int, shape (M, K)
        The column of each marker's k-th mate (Q, the NaN column, where the slot is empty).
    """

    values: FloatArray
    column: IntArray

    def misfits(self) -> FloatArray:
        """Every marker's misfit at every frame, ``(F, M)`` tolerances (:func:`misfits`)."""
        return _trimmed_mean_last(self.values[:, self.column])


def residual_table(
    positions: FloatArray, mate_index: IntArray, stats: PairStats, tolerance: FloatArray
) -> ResidualTable:
    """The residuals of every mate pair of a take.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    mate_index : ndarray of int, shape (M, K)
        -1 padded (:func:`mocapqa.markers.segments.mates`).
    stats : PairStats
    tolerance : ndarray, shape (M, M)
        Take units (:func:`tolerances`).

    Returns
    -------
    ResidualTable
    """
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
    return ResidualTable(values, column)


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
    return residual_table(positions, mate_index, stats, tolerance).misfits()


def pair_misfit(
    positions: FloatArray,
    table: ResidualTable,
    mover: IntArray,
    other: IntArray,
    mate_index: IntArray,
    stats: PairStats,
    tolerance: FloatArray,
    exchanged: bool,
) -> FloatArray:
    """``(F, P)`` misfit of each pair's marker ``mover`` against its mates other than ``other``
    (their distance does not change in an exchange), at its own positions or, when
    ``exchanged``, at ``other``'s.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    table : ResidualTable
        Of ``positions`` (:func:`residual_table`).
    mover, other : ndarray of int, shape (P,)
        The pairs' two markers.
    mate_index : ndarray of int, shape (M, K)
    stats : PairStats
    tolerance : ndarray, shape (M, M)
        Take units.
    exchanged : bool
        Whether ``mover`` is measured at ``other``'s positions.

    Returns
    -------
    ndarray, shape (F, P)
        Tolerances; NaN where unknown.
    """
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
