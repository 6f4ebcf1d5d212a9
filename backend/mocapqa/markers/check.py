"""The marker check of one take: gaps, labels, static markers, segments, swaps and spikes.

``check_markers(positions, names, fps, length_unit, params)`` runs the steps in order:

1. gaps and the per-marker gap summary (:mod:`mocapqa.markers.gaps`);
2. unlabelled and duplicate labels, static and absent markers (:mod:`mocapqa.markers.labels`);
3. the distance statistics of every marker pair and the segments they imply
   (:mod:`mocapqa.markers.segments`);
4. swaps (:mod:`mocapqa.markers.swaps`);
5. spikes (:mod:`mocapqa.markers.spikes`), confirmed by the misfit against rigid mates where a
   marker has them; the jumps at a swap's first and last frames are the swap's, not spikes.

Everything stays in take units; ``to_json`` names the unit of every size. Frames are 0-based,
ends inclusive; markers are named by the file's labels.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.markers.gaps import Gap, MarkerGaps, find_gaps, summarise_gaps
from mocapqa.markers.labels import LabelFinding, StaticMarker, find_label_problems, find_static
from mocapqa.markers.params import MarkerParams
from mocapqa.markers.segments import PairStats, Segment, infer_segments, pair_stats
from mocapqa.markers.spikes import Spike, find_spikes
from mocapqa.markers.swaps import Swap, swaps_and_misfits
from mocapqa.markers.take import check_take, visible

__all__ = ["MarkerReport", "check_markers"]

_SWAP_EDGE = 3
"""Spikes within this many frames of a swap's first or last frame, on one of its markers,
are the swap's jumps."""


@dataclass(frozen=True, slots=True)
class MarkerReport:
    """What the marker check found in a take.

    Parameters
    ----------
    names : tuple of str
        The M labels.
    frames : int
    fps : float
    length_unit : str
    gaps : tuple of Gap
        By marker, then start.
    gap_summary : tuple of MarkerGaps
        One per marker, in label order.
    labels : tuple of LabelFinding
    static : tuple of StaticMarker
    segments : tuple of Segment
    swaps : tuple of Swap
        By start frame.
    spikes : tuple of Spike
        By marker, then start.
    stats : PairStats
        Distance statistics of every pair (median, spread, rigid), take units.
    """

    names: tuple[str, ...]
    frames: int
    fps: float
    length_unit: str
    gaps: tuple[Gap, ...]
    gap_summary: tuple[MarkerGaps, ...]
    labels: tuple[LabelFinding, ...]
    static: tuple[StaticMarker, ...]
    segments: tuple[Segment, ...]
    swaps: tuple[Swap, ...]
    spikes: tuple[Spike, ...]
    stats: PairStats

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict: ``gaps``, ``swaps``, ``spikes``, ``segments``, ``static``,
        ``labels``, ``gap_summary`` and the take's ``frames``, ``fps``, ``length_unit``.

        Sizes are in the take's unit (``length_unit``; accelerations per s²); missing shares
        are 0–1; frames 0-based with inclusive ends.
        """
        unit = self.length_unit
        return {
            "frames": self.frames,
            "fps": self.fps,
            "length_unit": unit,
            "markers": list(self.names),
            "gaps": [
                {"marker": g.marker, "start": g.start, "end": g.end, "frames": g.frames,
                 "seconds": round(g.seconds, 6), "edge": g.edge, "severity": g.severity}
                for g in self.gaps
            ],
            "gap_summary": [
                {"marker": s.marker, "count": s.count, "longest": s.longest,
                 "longest_s": round(s.longest_s, 6), "missing": round(s.missing, 6)}
                for s in self.gap_summary
            ],
            "swaps": [
                {"markers": list(s.markers), "start": s.start, "end": s.end,
                 "confidence": s.confidence, "frames": s.end - s.start + 1,
                 "misfit": _finite(s.misfit), "repaired_misfit": _finite(s.repaired_misfit),
                 "crossing": list(s.crossing), "severity": s.severity}
                for s in self.swaps
            ],
            "spikes": [
                {"marker": s.marker, "start": s.start, "end": s.end, "peak": s.peak,
                 "size": s.size, "size_unit": f"{unit}/s^2", "offset": s.offset,
                 "offset_unit": unit, "ratio": round(s.ratio, 4), "severity": s.severity}
                for s in self.spikes
            ],
            "segments": [{"name": s.name, "markers": list(s.markers)} for s in self.segments],
            "static": [
                {"marker": s.marker, "kind": s.kind, "std": s.std, "std_unit": unit,
                 "severity": s.severity}
                for s in self.static
            ],
            "labels": [
                {"kind": f.kind, "label": f.label, "markers": list(f.names),
                 "severity": f.severity}
                for f in self.labels
            ],
        }  # fmt: skip


def _finite(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


def check_markers(
    positions: FloatArray,
    names: Sequence[str],
    fps: float,
    length_unit: str,
    params: MarkerParams | None = None,
) -> MarkerReport:
    """Check a marker take.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Marker positions in ``length_unit``, NaN where missing.
    names : sequence of str
        The M labels as the file writes them.
    fps : float
        Frames per second.
    length_unit : str
        "m", "cm", "mm" or "in" (any other is read as millimetres for the thresholds).
    params : MarkerParams, optional
        Thresholds (defaults when None).

    Returns
    -------
    MarkerReport

    Raises
    ------
    ShapeError
        If the arrays do not match.
    InputError
        If ``fps`` is not positive.
    """
    p = params or MarkerParams()
    array = check_take(positions, names, fps)
    labels = tuple(str(n) for n in names)
    present = visible(array)
    stats = pair_stats(array, length_unit, p)
    swaps, misfit = swaps_and_misfits(array, labels, stats, length_unit, p)
    spikes = [
        s
        for s in find_spikes(array, labels, fps, length_unit, p, misfit)
        if not any(
            s.index in w.indices
            and min(abs(s.peak - w.start), abs(s.peak - (w.end + 1))) <= _SWAP_EDGE
            for w in swaps
        )
    ]
    return MarkerReport(
        names=labels,
        frames=int(array.shape[0]),
        fps=float(fps),
        length_unit=length_unit,
        gaps=tuple(find_gaps(present, labels, fps, p)),
        gap_summary=tuple(summarise_gaps(present, labels, fps)),
        labels=tuple(find_label_problems(labels)),
        static=tuple(find_static(array, present, labels, length_unit, p)),
        segments=tuple(infer_segments(stats, labels)),
        swaps=tuple(swaps),
        spikes=tuple(spikes),
        stats=stats,
    )
