"""The run's marker step: checks, swap repair and gap filling of an optical marker take.

:func:`run_markers` calls :func:`mocapqa.markers.check.check_markers` for the findings and
:func:`mocapqa.markers.repair.repair_markers` for the corrected take: the swaps the
``confident`` rule applies repaired *before* any fill (a fill uses the data either side of its
gap), then the confident fills of the repaired take applied. Its findings share the run's
shape (``kind, joint, start_frame, end_frame, value, unit, confidence``; ``joint`` is the
marker's label, frames 0-based and inclusive):

* ``gap`` — a gap filled in the corrected take; ``value`` its expected error (cross-validated
  RMSE of the chosen method), ``method`` the method;
* ``gap not filled`` — a gap left missing; ``value`` the best method's expected error (None
  when no method could be tried), ``method`` None when no method fills it within the limit;
* ``swap`` — two labels exchanging trajectories (``markers``, ``joint`` the first);
  ``confidence`` 0–1, ``applied`` whether the corrected take has it repaired, ``value`` frames;
  ``id`` its position in the check's list, which the check finds again in the same order from
  the same take (the id a reviewer's decision names: :func:`decided_repair`);
* ``spike`` — ``value`` how far the sample leaves its smooth path;
* ``static marker``, ``absent marker`` — ``value`` the positions' spread (None when absent);
  ``unlabelled marker``, ``duplicate label`` — ``value`` None; all over the whole take.

Lengths are millimetres when the take's unit is metric (or inches), else take units. Every
finding carries the check's ``severity`` ("info", "warning", "error"); gaps, swaps and spikes
a one-line ``readout`` for the findings list.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection
from typing import Any, Literal

import numpy as np

from mocapqa.core.arrays import IntArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.markers.check import MarkerReport, check_markers
from mocapqa.markers.fill import GapFill
from mocapqa.markers.gaps import gap_severity
from mocapqa.markers.params import MM_PER_UNIT, MarkerParams
from mocapqa.markers.repair import MarkerRepair, repair_markers
from mocapqa.markers.segments import PairStats
from mocapqa.markers.swap_repair import repair_swaps
from mocapqa.pipeline.steps import Plot, StepOutcome

__all__ = [
    "MARKER_APPLY",
    "MARKER_FINDING_KINDS",
    "decided_repair",
    "marker_findings",
    "run_markers",
    "segment_sticks",
]

MARKER_FINDING_KINDS = (
    "gap",
    "gap not filled",
    "swap",
    "spike",
    "static marker",
    "absent marker",
    "unlabelled marker",
    "duplicate label",
)
"""The kinds of finding the marker step reports."""
MARKER_APPLY: Literal["confident"] = "confident"
"""The rule by which the run step repairs swaps and fills gaps (an undecided swap's)."""


def _length(value: float | None, unit: str) -> tuple[float | None, str]:
    """A length in mm for a known unit, else in take units; None for None or NaN."""
    scale = MM_PER_UNIT.get(unit)
    if value is None or not np.isfinite(value):
        return None, "mm" if scale else unit
    return (round(float(value) * scale, 3), "mm") if scale else (round(float(value), 6), unit)


def marker_findings(
    report: MarkerReport, repair: MarkerRepair, params: MarkerParams
) -> list[dict[str, Any]]:
    """The marker step's findings (kinds and fields in the module docstring).

    Parameters
    ----------
    report : MarkerReport
        The check of the take as read.
    repair : MarkerRepair
        The swaps repaired and the gaps of the repaired take (filled or not).
    params : MarkerParams
        The check's thresholds (gap severity of a gap the repair moved).
    """
    severity = {(g.marker, g.start, g.end): g.severity for g in report.gaps}
    findings = [_gap_finding(gap, report, severity, params) for gap in repair.fills.gaps]
    repaired = {(s.markers, s.start, s.end) for s in repair.repaired}
    for number, swap in enumerate(report.swaps):
        findings.append({
            "kind": "swap",
            "joint": swap.markers[0],
            "start_frame": swap.start,
            "end_frame": swap.end,
            "value": swap.end - swap.start + 1,
            "unit": "frames",
            "confidence": round(float(swap.confidence), 3),
            "markers": list(swap.markers),
            "id": number,
            "applied": (swap.markers, swap.start, swap.end) in repaired,
            "severity": swap.severity,
            "readout": f"{' ↔ '.join(swap.markers)}, "
            f"{'' if (swap.markers, swap.start, swap.end) in repaired else 'not '}repaired",
        })  # fmt: skip
    return findings + _take_findings(report)


def _gap_finding(
    gap: GapFill,
    report: MarkerReport,
    severity: dict[tuple[str, int, int], str],
    params: MarkerParams,
) -> dict[str, Any]:
    """The ``gap`` or ``gap not filled`` finding of one gap of the repaired take."""
    name = report.names[gap.marker]
    error, error_unit = _length(gap.expected_error, report.length_unit)
    seconds = (gap.end - gap.start + 1) / report.fps
    expected = "no method could fill it" if error is None else (
        f"expected error {error:g} {error_unit}"
    )  # fmt: skip
    if gap.applied:
        readout = f"filled ({gap.method}), {expected}"
    elif gap.method is not None:
        readout = f"not filled: {expected} ({gap.method}), not confident"
    else:
        readout = f"not filled: {expected}"
    return {
        "kind": "gap" if gap.applied else "gap not filled",
        "joint": name,
        "start_frame": gap.start,
        "end_frame": gap.end,
        "value": error,
        "unit": error_unit,
        "confidence": None,
        "method": gap.method,
        "confident": gap.confident,
        "applied": gap.applied,
        "seconds": round(seconds, 6),
        "severity": severity.get((name, gap.start, gap.end), gap_severity(seconds, params)),
        "readout": readout,
    }


def _take_findings(report: MarkerReport) -> list[dict[str, Any]]:
    """The ``spike``, ``static marker``, ``absent marker``, ``unlabelled marker`` and
    ``duplicate label`` findings of the take as read."""
    unit, last = report.length_unit, report.frames - 1
    findings: list[dict[str, Any]] = []
    for spike in report.spikes:
        offset, offset_unit = _length(spike.offset, unit)
        findings.append({
            "kind": "spike", "joint": spike.marker, "start_frame": spike.start,
            "end_frame": spike.end, "value": offset, "unit": offset_unit, "confidence": None,
            "peak": spike.peak, "severity": spike.severity,
            "readout": f"peak at frame {spike.peak}",
        })  # fmt: skip
    for static in report.static:
        spread, spread_unit = _length(static.std, unit)
        findings.append({
            "kind": f"{static.kind} marker", "joint": static.marker, "start_frame": 0,
            "end_frame": last, "value": spread, "unit": spread_unit, "confidence": None,
            "severity": static.severity,
        })  # fmt: skip
    for label in report.labels:
        kind = "unlabelled marker" if label.kind == "unlabelled" else "duplicate label"
        findings.extend(
            {"kind": kind, "joint": name, "start_frame": 0, "end_frame": last, "value": None,
             "unit": "", "confidence": None, "label": label.label, "severity": label.severity}
            for name in label.names
        )  # fmt: skip
    return findings


def segment_sticks(stats: PairStats, segments: list[list[int]]) -> list[list[int]]:
    """Sticks that draw each segment: the shortest tree joining its markers (Prim's, on the
    markers' median distances), as ``[a, b]`` marker index pairs."""
    sticks: list[list[int]] = []
    for members in segments:
        distance = np.where(np.isfinite(stats.median), stats.median, np.inf)
        joined, rest = [members[0]], list(members[1:])
        while rest:
            a, b = min(((a, b) for a in joined for b in rest), key=lambda ab: distance[ab])
            sticks.append([a, b])
            joined.append(b)
            rest.remove(b)
    return sticks


def _repair(
    sequence: KeypointSequence, params: MarkerParams, swaps: Collection[int] | None = None
) -> MarkerRepair:
    """:func:`~mocapqa.markers.repair.repair_markers` of a take as the run step does it."""
    # A keypoint take carries no residuals: -1 where missing, 1 (measured) elsewhere.
    residuals = np.where(sequence.missing, -1.0, 1.0)
    return repair_markers(
        sequence.positions,
        residuals,
        sequence.names,
        sequence.fps,
        sequence.length_unit,
        MARKER_APPLY,
        params,
        swaps=swaps,
    )


def decided_repair(
    sequence: KeypointSequence, swaps: Collection[int], params: MarkerParams | None = None
) -> MarkerRepair:
    """The repair of a marker take with a reviewer's choice of swaps: exactly the swaps
    ``swaps`` names (ids as in the ``swap`` findings) exchanged, then the gaps of that take
    filled by the run's own rule (the confident fills, chosen again on it).

    Raises
    ------
    InputError
        If ``swaps`` names an id the check does not find.
    """
    return _repair(sequence, params or MarkerParams(), swaps)


def run_markers(sequence: KeypointSequence, params: MarkerParams | None = None) -> StepOutcome:
    """Check a marker take, repair its confident swaps, then fill its confident gaps.

    Returns
    -------
    StepOutcome
        Findings as in the module docstring; ``keypoints`` the corrected take (filled samples
        with confidence 1), ``markers`` the :class:`~mocapqa.markers.repair.MarkerRepair` (its
        ``filled`` mask marks the filled samples); the plot's series hold the gap summary, the
        segments and their ``sticks``.
    """
    p = params or MarkerParams()
    unit = sequence.length_unit
    report = check_markers(sequence.positions, sequence.names, sequence.fps, unit, p)
    repair = _repair(sequence, p)
    exchanged = repair_swaps(sequence.confidence, repair.repaired)
    corrected = dataclasses.replace(
        sequence, positions=repair.positions, confidence=np.where(repair.filled, 1.0, exchanged)
    )
    findings = marker_findings(report, repair, p)
    index = {name: m for m, name in enumerate(report.names)}
    members = [[index[n] for n in s.markers] for s in report.segments]
    detail = report.to_json()
    series = {
        "length_unit": unit,
        "gap_summary": detail["gap_summary"],
        "segments": detail["segments"],
        "sticks": segment_sticks(report.stats, members),
        "filled_samples": int(repair.filled.sum()),
    }
    edges: IntArray = np.asarray(
        [f["start_frame"] for f in findings] + [f["end_frame"] for f in findings], dtype=np.intp
    )
    n_gaps = sum(f["kind"].startswith("gap") for f in findings)
    filled = sum(f["kind"] == "gap" for f in findings)
    return StepOutcome(
        "done",
        f"{n_gaps} gap(s), {filled} filled ({int(repair.filled.sum())} samples, confident "
        f"fills); {len(report.swaps)} swap(s), {len(repair.repaired)} repaired; "
        f"{len(report.spikes)} spike(s); {len(report.segments)} segment(s) inferred",
        findings,
        Plot(np.empty((sequence.n_frames, 0)), edges, lambda frames: series),
        keypoints=corrected,
        markers=repair,
    )
