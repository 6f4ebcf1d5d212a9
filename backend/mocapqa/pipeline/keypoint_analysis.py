"""The analysis of a keypoint take (video keypoints, or a C3D or TRC marker take): the marker
check (marker takes only), the feet check, the keypoint filter and the foot locks.

Swaps are repaired and gaps filled first (a marker take's ``markers`` check), the feet of the
take as read are checked, the repaired take is filtered (adaptive unless a filter is chosen)
and the run's foot locks are pinned last, on the filtered take and on the marker repair the
run's corrected C3D is written from. Missing keypoints stay NaN.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from mocapqa import __version__
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError
from mocapqa.markers.repair import MarkerRepair
from mocapqa.pipeline.analysis_parts import (
    AnalysisResult,
    ProgressCallback,
    feet_locks,
    feet_step,
    no_progress,
    report_summary,
    series_json,
    steps_json,
)
from mocapqa.pipeline.marker_step import run_markers
from mocapqa.pipeline.options import DEFAULT_KEYPOINT_FILTER, AnalysisOptions, take_checks
from mocapqa.pipeline.step_log import StepLog, requested
from mocapqa.pipeline.steps import run_filter_keypoints

__all__ = ["analyze_keypoints"]


def _keypoint_markers(
    sequence: KeypointSequence,
    options: AnalysisOptions,
    progress: ProgressCallback,
    steps: StepLog,
) -> KeypointSequence:
    """The marker check of a marker take (swaps repaired, gaps filled); returns the repaired
    take, or the take as read when the check did not run or changed nothing."""
    if "markers" not in take_checks("keypoints", sequence.source_format):
        reason = "video keypoints are detections, not markers (C3D and TRC takes only)"
        steps.skip("markers", reason)
        return sequence
    if not requested("markers", options, steps):
        return sequence
    progress(15, "checking markers, repairing swaps, filling gaps")
    outcome = steps.record("markers", run_markers(sequence))
    return outcome.keypoints if outcome.keypoints is not None else sequence


def _keypoint_filter(
    corrected: KeypointSequence,
    options: AnalysisOptions,
    progress: ProgressCallback,
    steps: StepLog,
) -> KeypointSequence:
    """The keypoint filter (adaptive unless one is chosen); returns the filtered take."""
    if not requested("filter", options, steps):
        return corrected
    progress(30, "filtering keypoints")
    outcome = run_filter_keypoints(
        corrected,
        options.filter_method or DEFAULT_KEYPOINT_FILTER,
        options.filter_preset,
        options.filter_params,
    )
    steps.record("filter", outcome)
    return outcome.keypoints if outcome.keypoints is not None else corrected


def _keypoint_facts(sequence: KeypointSequence) -> dict[str, Any]:
    """What the summary of a keypoint take says of its points."""
    return {
        "n_keypoints": sequence.n_keypoints,
        "length_unit": sequence.length_unit,
        "missing_fraction": sequence.missing_fraction,
        "assumptions": list(sequence.assumptions),
    }


def analyze_keypoints(
    sequence: KeypointSequence, options: AnalysisOptions, progress: ProgressCallback
) -> AnalysisResult:
    """Analyse a keypoint take.

    Parameters
    ----------
    sequence : KeypointSequence
        The take as read.
    options : AnalysisOptions
        What to run.
    progress : callable
        Called as ``progress(percent, step)`` with percent in 0–100.

    Returns
    -------
    AnalysisResult

    Raises
    ------
    InputError
        When ``options`` has a mapping (BVH takes only).
    """
    if options.mapping:
        raise InputError("Expected the mapping option only for BVH takes, got a keypoint take")
    steps = StepLog()
    steps.skip("twist", "keypoint takes have no joint rotations")
    steps.skip("limits", "keypoint takes have no joint rotations")
    corrected = _keypoint_markers(sequence, options, progress, steps)
    feet_step(sequence, options, progress, 25, steps)  # the feet of the take as read
    filtered = _keypoint_filter(corrected, options, progress, steps)
    filtered = feet_locks(sequence, filtered, options, progress, steps)
    progress(85, "collecting results")
    # Missing keypoints stay NaN: drawing them at the origin would show points never seen.
    points: dict[str, Any] = {
        "names": list(sequence.names),
        "parents": [-1] * sequence.n_keypoints,
        "n_joints": sequence.n_keypoints,
    }
    series = series_json(steps.plotted, sequence.n_frames, sequence.fps, options.max_points)
    if series.get("markers"):  # the inferred segments, drawn as sticks
        points["bones"] = series["markers"]["sticks"]
    report = {
        "kind": "keypoints",
        "version": __version__,
        "summary": report_summary(sequence, _keypoint_facts(sequence), steps.findings),
        "options": options.to_json(),
        "steps": steps_json(steps.outcomes),
        "findings": steps.findings,
        "points": points,
        "series": series,
    }
    markers = _locked_repair(sequence, steps.outcomes["markers"].markers, options, steps)
    return AnalysisResult(
        report,
        None,
        filtered,
        sequence.positions,
        filtered.positions,
        confidence=sequence.confidence,
        bridged=steps.outcomes["filter"].bridged,
        markers=markers,
    )


def _locked_repair(
    sequence: KeypointSequence,
    repair: MarkerRepair | None,
    options: AnalysisOptions,
    steps: StepLog,
) -> MarkerRepair | None:
    """The marker repair (what the run's corrected C3D is written from) with the run's foot
    locks pinned on its positions too, as on the filtered take
    (:func:`mocapqa.pipeline.analysis_parts.feet_locks`)."""
    if repair is None:
        return None
    repaired = dataclasses.replace(sequence, positions=repair.positions)
    pinned = feet_locks(sequence, repaired, options, no_progress, steps)
    if pinned is repaired:
        return repair
    return dataclasses.replace(repair, positions=pinned.positions)
