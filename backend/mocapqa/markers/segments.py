"""Segments inferred from the take: marker pairs whose distance stays near-constant.

Conventions
-----------
* The distance of every marker pair is measured on at most ``segment_frames`` frames spaced
  evenly over the take, over the frames where both markers are visible.
* Per pair: the median distance, and the spread (10th to 90th percentile). A pair is
  **rigid** when the spread is at most ``rigid_spread`` (mm) plus ``rigid_relative`` times
  the median distance and both markers are seen together on at least ``rigid_min_visible``
  of the sampled frames: the two ride on one segment (skin markers on one bone move by a few
  millimetres against each other; across a joint the distance changes by centimetres).
* A marker's **mates** are its ``max_mates`` most rigid partners (smallest spread relative to
  the threshold); they are what the swap test measures against.
* **Segments** group markers by complete linkage on the rigidity score (spread over the
  threshold), cut at 1: every pair inside a segment is rigid. A marker rigid to nothing is in
  no segment. Segments are named by their members; :data:`KNOWN_SEGMENTS` names the common
  Plug-in Gait and CMU 41 groups when a segment holds most of one.
* The percentiles come from one sort along time (NaN sorts last), so the time is that of
  sorting the ``S × M × (M + 1) / 2`` distances of the pairs, S ≤ ``segment_frames``; the
  pairs are taken a block of markers at a time, so the memory stays near ``_BLOCK_VALUES``
  distances whatever M (the upload limit ``max_markers`` bounds M, and so the time).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.markers.labels import base_label
from mocapqa.markers.params import MarkerParams, unit_scale

__all__ = [
    "KNOWN_SEGMENTS",
    "PairStats",
    "Segment",
    "infer_segments",
    "mates",
    "nearest",
    "pair_stats",
]

KNOWN_SEGMENTS: dict[str, frozenset[str]] = {
    "head": frozenset({"LFHD", "RFHD", "LBHD", "RBHD", "ARIEL"}),
    "thorax": frozenset({"C7", "T10", "CLAV", "STRN", "RBAK"}),
    "pelvis": frozenset({"LASI", "RASI", "LPSI", "RPSI", "SACR", "LFWT", "RFWT", "LBWT", "RBWT"}),
    "left thigh": frozenset({"LTHI", "LKNE", "LTHIGH", "LKNEE"}),
    "right thigh": frozenset({"RTHI", "RKNE", "RTHIGH", "RKNEE"}),
    "left shank": frozenset({"LTIB", "LANK", "LSHN", "LKNE"}),
    "right shank": frozenset({"RTIB", "RANK", "RSHN", "RKNE"}),
    "left foot": frozenset({"LHEE", "LTOE", "LMT5", "LANK", "LMT1"}),
    "right foot": frozenset({"RHEE", "RTOE", "RMT5", "RANK", "RMT1"}),
    "left upper arm": frozenset({"LSHO", "LUPA", "LELB", "LARM"}),
    "right upper arm": frozenset({"RSHO", "RUPA", "RELB", "RARM"}),
    "left forearm": frozenset({"LFRM", "LWRA", "LWRB", "LELB", "LFRA"}),
    "right forearm": frozenset({"RFRM", "RWRA", "RWRB", "RELB", "RFRA"}),
    "left hand": frozenset({"LFIN", "LWRA", "LWRB", "LTHMB"}),
    "right hand": frozenset({"RFIN", "RWRA", "RWRB", "RTHMB"}),
}
"""Common Plug-in Gait / CMU 41 / Vicon full-body groups, by label without subject prefix."""


@dataclass(frozen=True, slots=True)
class PairStats:
    """Distance statistics of every marker pair.

    Parameters
    ----------
    median : ndarray, shape (M, M)
        Median distance, take units (NaN for pairs never seen together, and on the diagonal).
    spread : ndarray, shape (M, M)
        90th minus 10th percentile of the distance, take units (NaN likewise).
    threshold : ndarray, shape (M, M)
        The largest spread of a rigid pair, take units.
    rigid : ndarray of bool, shape (M, M)
        Symmetric; False on the diagonal.
    """

    median: FloatArray
    spread: FloatArray
    threshold: FloatArray
    rigid: BoolArray

    @property
    def score(self) -> FloatArray:
        """Spread over threshold, ``(M, M)``: below 1 for rigid pairs, inf where unknown."""
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = self.spread / self.threshold
        score: FloatArray = np.where(np.isfinite(ratio), ratio, np.inf)
        return score


@dataclass(frozen=True, slots=True)
class Segment:
    """A group of markers riding on one body part.

    Parameters
    ----------
    name : str
        A known name (:data:`KNOWN_SEGMENTS`) or ``segment N``.
    markers : tuple of str
    """

    name: str
    markers: tuple[str, ...]


_BLOCK_VALUES = 1 << 21
"""Distances :func:`pair_stats` holds at once (sampled frames × markers × block width): with
the coordinate differences, about 32 bytes each, 64 MB."""


def _sample(n_frames: int, limit: int) -> IntArray:
    if n_frames <= limit:
        return np.arange(n_frames, dtype=np.intp)
    return np.unique(np.linspace(0, n_frames - 1, limit).round().astype(np.intp))


def _block_stats(
    sampled: FloatArray, start: int, columns: slice
) -> tuple[IntArray, FloatArray, FloatArray]:
    """Count, median and spread of the distances of markers ``start:`` to the ``columns``
    markers, each ``(M - start, C)``, from one sort along time (NaN sorts last)."""
    diff = sampled[:, start:, None, :] - sampled[:, None, columns, :]
    distances = np.einsum("smnk,smnk->smn", diff, diff)  # (S, M - start, C), NaN if missing
    del diff
    np.sqrt(distances, out=distances)
    counts = np.isfinite(distances).sum(axis=0)
    distances.sort(axis=0)

    def percentile(q: float) -> FloatArray:
        index = np.clip(np.round(q * (counts - 1)).astype(np.intp), 0, None)
        value: FloatArray = np.take_along_axis(distances, index[None], axis=0)[0]
        return np.where(counts > 0, value, np.nan)

    return counts, percentile(0.5), percentile(0.9) - percentile(0.1)


def pair_stats(
    positions: FloatArray, length_unit: str, params: MarkerParams | None = None
) -> PairStats:
    """Median and spread of every pair's distance, and which pairs are rigid.

    The pairs are measured a block of markers at a time, each block against the markers from
    its first on (the statistics are symmetric), so the memory held at once is about
    ``_BLOCK_VALUES`` distances whatever the marker count; the time still grows with the
    number of pairs.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    length_unit : str
    params : MarkerParams, optional

    Returns
    -------
    PairStats
    """
    p = params or MarkerParams()
    n_markers = positions.shape[1]
    sampled = positions[_sample(positions.shape[0], p.segment_frames)]
    counts = np.zeros((n_markers, n_markers), dtype=np.intp)
    median = np.full((n_markers, n_markers), np.nan)
    spread = np.full((n_markers, n_markers), np.nan)
    width = max(1, _BLOCK_VALUES // max(1, sampled.shape[0] * n_markers))
    for start in range(0, n_markers, width):
        columns = slice(start, min(start + width, n_markers))
        block = _block_stats(sampled, start, columns)
        for whole, part in zip((counts, median, spread), block, strict=True):
            whole[start:, columns] = part
            whole[columns, start:] = part.T
    threshold = p.rigid_spread * unit_scale(length_unit) + p.rigid_relative * median
    enough = counts >= max(2, p.rigid_min_visible * sampled.shape[0])
    off_diagonal = ~np.eye(n_markers, dtype=bool)
    with np.errstate(invalid="ignore"):
        rigid = enough & off_diagonal & (spread <= threshold)
    median = np.where(off_diagonal & enough, median, np.nan)
    spread = np.where(off_diagonal & enough, spread, np.nan)
    return PairStats(median, spread, threshold, rigid)


def mates(stats: PairStats, max_mates: int, max_score: float = 1.0) -> IntArray:
    """Each marker's most rigid partners, ``(M, K)`` with K = ``max_mates``, -1 padded.

    Parameters
    ----------
    stats : PairStats
    max_mates : int
    max_score : float
        Partners whose spread is at most this many times the rigid threshold count (1: the
        rigid pairs only).

    Returns
    -------
    ndarray of int, shape (M, max_mates)
        Partner indices by increasing rigidity score; -1 where a marker has fewer.
    """
    score = stats.score
    score = np.where(score <= max_score, score, np.inf)
    order = np.argsort(score, axis=1, kind="stable")[:, :max_mates]
    kept = np.take_along_axis(score, order, axis=1)
    result: IntArray = np.where(np.isfinite(kept), order, -1).astype(np.intp)
    return result


def nearest(stats: PairStats, count: int) -> IntArray:
    """Each marker's ``count`` nearest markers by median distance, ``(M, count)``, -1 padded."""
    distance = np.where(np.isfinite(stats.median), stats.median, np.inf)
    order = np.argsort(distance, axis=1, kind="stable")[:, :count]
    kept = np.take_along_axis(distance, order, axis=1)
    result: IntArray = np.where(np.isfinite(kept), order, -1).astype(np.intp)
    return result


def infer_segments(stats: PairStats, names: Sequence[str]) -> list[Segment]:
    """Groups of markers whose every pair is rigid (complete linkage on the rigidity score).

    Parameters
    ----------
    stats : PairStats
    names : sequence of str

    Returns
    -------
    list of Segment
        Of two or more markers, by their first marker's index.
    """
    from scipy.cluster.hierarchy import fcluster, linkage
    from scipy.spatial.distance import squareform

    n_markers = len(names)
    if n_markers < 2:
        return []
    score = np.minimum(stats.score, 1e6)
    score = np.minimum(score, score.T)
    np.fill_diagonal(score, 0.0)
    tree = linkage(squareform(score, checks=False), method="complete")
    labels = fcluster(tree, t=1.0, criterion="distance")
    groups: dict[int, list[int]] = {}
    for m, label in enumerate(labels):
        groups.setdefault(int(label), []).append(m)
    members = sorted((g for g in groups.values() if len(g) > 1), key=lambda g: g[0])
    segments: list[Segment] = []
    used: set[str] = set()
    for number, group in enumerate(members, start=1):
        bases = {base_label(names[m]) for m in group}
        best = max(
            (k for k in KNOWN_SEGMENTS if k not in used),
            key=lambda k: len(KNOWN_SEGMENTS[k] & bases),
            default=None,
        )
        if best is not None and 2 * len(KNOWN_SEGMENTS[best] & bases) > len(bases):
            used.add(best)
            name = best
        else:
            name = f"segment {number}"
        segments.append(Segment(name, tuple(names[m] for m in group)))
    return segments
