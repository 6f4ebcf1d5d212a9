"""One analysis of a take: twist refinement, joint limits, marker checks, the feet check and
filtering, with progress.

``analyze(take, options, progress)`` calls the algorithm entry points and gathers what the UI
and the downloads need into an :class:`AnalysisResult`:

* ``report`` — JSON-ready: summary, per-step state, findings, and the plotted time series
  on one frame axis of at most ``options.max_points`` frames that keeps every series' peaks
  and every finding's first and last frame (:func:`series_json`);
* the corrected motion (twist-refined, optionally filtered) or the filtered keypoints (of a
  marker take: swaps repaired and gaps filled first, the filled samples marked);
* raw and corrected point positions ``(F, P, 3)`` for the 3D view (served in windows).

Each algorithm step lives in :mod:`mocapqa.pipeline.steps`; a step that does not apply (a rig
without a limits model, a keypoint take for twist) reports why, and the take passes through.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from mocapqa import __version__
from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.decimate import peak_frames
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles
from mocapqa.errors import InputError
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.limits.catalog import DEFAULT_MODEL, ModelCatalog
from mocapqa.markers.repair import MarkerRepair
from mocapqa.pipeline.feet_step import run_feet
from mocapqa.pipeline.frames import motion_pose, rigid_bones
from mocapqa.pipeline.loading import Take
from mocapqa.pipeline.marker_step import run_markers
from mocapqa.pipeline.options import AnalysisOptions, take_checks
from mocapqa.pipeline.steps import (
    StepOutcome,
    run_filter_keypoints,
    run_filter_motion,
    run_limits,
    run_twist,
)

__all__ = ["AnalysisResult", "ProgressCallback", "analyze", "series_json"]

ProgressCallback = Callable[[int, str], None]
"""Called as ``progress(percent, step)`` with percent in 0–100."""


@dataclass(frozen=True, slots=True)
class AnalysisResult:
    """Everything one run produces.

    Parameters
    ----------
    report : dict
        JSON-ready report (summary, steps, findings, series).
    corrected_motion : Motion, optional
        Twist-refined (and optionally filtered) motion, for BVH takes.
    filtered_keypoints : KeypointSequence, optional
        Filtered keypoints, for keypoint takes.
    raw_points : ndarray, shape (F, P, 3)
        Positions drawn in the raw 3D view, file units.
    corrected_points : ndarray, shape (F, P, 3)
        Positions drawn in the corrected 3D view, file units.
    raw_rotations, corrected_rotations : ndarray, shape (F, P, 4), optional
        World unit quaternions (scalar-last) of the points, for motion takes: the 3D view
        orients each bone by its parent's rotation.
    confidence : ndarray, shape (F, P), optional
        Detection confidence in [0, 1] of each point, for keypoint takes (0 where missing).
    bridged : ndarray of bool, shape (F, P), optional
        Samples the keypoint filter bridged (no valid input), for filtered keypoint takes.
    markers : MarkerRepair, optional
        The marker step's repaired and filled take, for marker takes it checked; its
        ``filled`` mask marks the filled samples.
    """

    report: dict[str, Any]
    corrected_motion: Motion | None
    filtered_keypoints: KeypointSequence | None
    raw_points: FloatArray
    corrected_points: FloatArray
    raw_rotations: FloatArray | None = None
    corrected_rotations: FloatArray | None = None
    confidence: FloatArray | None = None
    bridged: BoolArray | None = None
    markers: MarkerRepair | None = None


def _no_progress(percent: int, step: str) -> None:
    del percent, step


def _steps_json(outcomes: dict[str, StepOutcome]) -> dict[str, dict[str, str]]:
    return {name: {"state": o.state, "message": o.message} for name, o in outcomes.items()}


def series_json(
    outcomes: Mapping[str, StepOutcome], n_frames: int, fps: float, max_points: int
) -> dict[str, Any]:
    """The plotted series of a run's steps, sampled on one frame axis that keeps their peaks.

    The axis is :func:`mocapqa.core.decimate.peak_frames` of every step's plotted series
    together, keeping the steps' findings' frames first, in the steps' order (each twist
    interval's first frame and offset steps, largest first; then the limits findings' first
    frames and last frames, worst first): ``frames`` is shared by all series, as the page and
    API clients read it.

    Parameters
    ----------
    outcomes : mapping of str to StepOutcome
        The steps that ran, by name; a step without a plot (no model) gives None.
    n_frames : int
        Frames of the take.
    fps : float
        Frame rate, frames per second.
    max_points : int
        Most frames kept.
    """
    plots = [o.plot for o in outcomes.values() if o.plot is not None]
    signals = np.concatenate([np.empty((n_frames, 0))] + [p.signals for p in plots], axis=1)
    keep = np.concatenate([np.empty(0, dtype=np.intp)] + [p.keep for p in plots])
    frames = peak_frames(signals, max_points, keep)
    series: dict[str, Any] = {"frames": frames.tolist(), "fps": fps}
    for name, outcome in outcomes.items():
        series[name] = None if outcome.plot is None else outcome.plot.at(frames)
    return series


def _analyze_motion(
    motion: Motion,
    options: AnalysisOptions,
    progress: ProgressCallback,
    catalog: ModelCatalog | None,
) -> AnalysisResult:
    outcomes: dict[str, StepOutcome] = {}
    plotted: dict[str, StepOutcome] = {}
    findings: list[dict[str, Any]] = []
    timings: dict[str, float] = {}

    rig = find_roles(motion.skeleton, options.mapping)  # a bad mapping fails the run here
    progress(10, "forward kinematics (raw)")
    clock = time.perf_counter()
    names, parents, raw_points, raw_rotations = motion_pose(motion)
    timings["fk_raw_s"] = time.perf_counter() - clock

    corrected = motion
    if "twist" in options.checks:
        progress(25, "twist analysis")
        clock = time.perf_counter()
        outcome = run_twist(motion, options.twist_method, options.mapping, options.twist_apply)
        timings["twist_s"] = time.perf_counter() - clock
        outcomes["twist"] = plotted["twist"] = outcome
        if outcome.motion is not None:
            corrected = outcome.motion
        findings += outcome.findings
    else:
        outcomes["twist"] = StepOutcome("skipped", "not requested")

    if "limits" in options.checks:
        progress(55, "joint-limit check")
        clock = time.perf_counter()
        twist_outcome = outcomes.get("twist")
        outcome = run_limits(
            motion,
            options.mapping,
            options.limits_model or DEFAULT_MODEL,
            catalog,
            twist_findings=twist_outcome.findings if twist_outcome else None,
        )
        timings["limits_s"] = time.perf_counter() - clock
        outcomes["limits"] = plotted["limits"] = outcome
        findings += outcome.findings
    else:
        outcomes["limits"] = StepOutcome("skipped", "not requested")

    if "feet" in options.checks:
        progress(65, "feet and floor check")
        clock = time.perf_counter()
        outcome = run_feet(motion, options.mapping)
        timings["feet_s"] = time.perf_counter() - clock
        outcomes["feet"] = outcome
        if outcome.state == "done":
            plotted["feet"] = outcome
        findings += outcome.findings
    else:
        outcomes["feet"] = StepOutcome("skipped", "not requested")

    if "filter" in options.checks and options.filter_method:
        progress(75, "filtering the corrected motion")
        clock = time.perf_counter()
        outcome = run_filter_motion(corrected, options.filter_method, options.filter_params)
        timings["filter_s"] = time.perf_counter() - clock
        outcomes["filter"] = outcome
        if outcome.motion is not None:
            corrected = outcome.motion
    else:
        outcomes["filter"] = StepOutcome("skipped", "no filter chosen for motion takes")
    outcomes["markers"] = StepOutcome("skipped", "BVH takes have joints, not markers")

    progress(85, "forward kinematics (corrected)")
    clock = time.perf_counter()
    _, _, corrected_points, corrected_rotations = motion_pose(corrected)
    timings["fk_corrected_s"] = time.perf_counter() - clock
    clock = time.perf_counter()
    series = series_json(plotted, motion.n_frames, motion.fps, options.max_points)
    timings["series_s"] = time.perf_counter() - clock
    skeleton = motion.skeleton
    report = {
        "kind": "motion",
        "version": __version__,
        "summary": {
            "n_frames": motion.n_frames,
            "fps": motion.fps,
            "duration_s": motion.n_frames / motion.fps,
            "n_joints": skeleton.n_joints,
            "length_unit": skeleton.length_unit,
            "root_translation": skeleton.root_translation,
            "bind_pose_frames": leading_bind_pose(motion.quats),
            "roles": {key: skeleton.names[j] for key, j in sorted(rig.roles.items())},
            "missing_roles": list(rig.unmapped),
            "n_findings": len(findings),
            "findings_by_kind": _count_by_kind(findings),
        },
        "options": options.to_json(),
        "steps": _steps_json(outcomes),
        "timings_s": {k: round(v, 4) for k, v in timings.items()},
        "findings": findings,
        "points": {
            "names": names,
            "parents": parents,
            "bones": rigid_bones(motion),
            "n_joints": skeleton.n_joints,
        },
        "series": series,
    }
    return AnalysisResult(
        report,
        corrected,
        None,
        raw_points,
        corrected_points,
        raw_rotations,
        corrected_rotations,
    )


def _analyze_keypoints(
    sequence: KeypointSequence, options: AnalysisOptions, progress: ProgressCallback
) -> AnalysisResult:
    if options.mapping:
        raise InputError("Expected the mapping option only for BVH takes, got a keypoint take")
    outcomes: dict[str, StepOutcome] = {
        "twist": StepOutcome("skipped", "keypoint takes have no joint rotations"),
        "limits": StepOutcome("skipped", "keypoint takes have no joint rotations"),
    }
    plotted: dict[str, StepOutcome] = {}
    findings: list[dict[str, Any]] = []
    correction: MarkerRepair | None = None
    corrected = sequence
    if "markers" not in take_checks("keypoints", sequence.source_format):
        reason = "video keypoints are detections, not markers (C3D and TRC takes only)"
        outcomes["markers"] = StepOutcome("skipped", reason)
    elif "markers" in options.checks:
        progress(15, "checking markers, repairing swaps, filling gaps")
        outcome = run_markers(sequence)
        outcomes["markers"] = plotted["markers"] = outcome
        correction = outcome.markers
        if outcome.keypoints is not None:
            corrected = outcome.keypoints
        findings += outcome.findings
    else:
        outcomes["markers"] = StepOutcome("skipped", "not requested")
    if "feet" in options.checks:  # the feet of the take as read
        progress(25, "feet and floor check")
        outcome = run_feet(sequence)
        outcomes["feet"] = outcome
        if outcome.state == "done":
            plotted["feet"] = outcome
        findings += outcome.findings
    else:
        outcomes["feet"] = StepOutcome("skipped", "not requested")
    filtered = corrected
    if "filter" in options.checks:
        progress(30, "filtering keypoints")
        outcome = run_filter_keypoints(
            corrected,
            options.filter_method or "adaptive",
            options.filter_preset,
            options.filter_params,
        )
        outcomes["filter"] = plotted["filter"] = outcome
        if outcome.keypoints is not None:
            filtered = outcome.keypoints
        findings += outcome.findings
    else:
        outcomes["filter"] = StepOutcome("skipped", "not requested")
    progress(85, "collecting results")
    # Missing keypoints stay NaN: drawing them at the origin would show points never seen.
    raw_points = sequence.positions
    corrected_points = filtered.positions
    points: dict[str, Any] = {
        "names": list(sequence.names),
        "parents": [-1] * sequence.n_keypoints,
        "n_joints": sequence.n_keypoints,
    }
    series = series_json(plotted, sequence.n_frames, sequence.fps, options.max_points)
    if series.get("markers"):  # the inferred segments, drawn as sticks
        points["bones"] = series["markers"]["sticks"]
    report = {
        "kind": "keypoints",
        "version": __version__,
        "summary": {
            "n_frames": sequence.n_frames,
            "fps": sequence.fps,
            "duration_s": sequence.n_frames / sequence.fps,
            "n_keypoints": sequence.n_keypoints,
            "length_unit": sequence.length_unit,
            "missing_fraction": sequence.missing_fraction,
            "assumptions": list(sequence.assumptions),
            "n_findings": len(findings),
            "findings_by_kind": _count_by_kind(findings),
        },
        "options": options.to_json(),
        "steps": _steps_json(outcomes),
        "findings": findings,
        "points": points,
        "series": series,
    }
    bridged = outcomes["filter"].bridged
    return AnalysisResult(
        report,
        None,
        filtered,
        raw_points,
        corrected_points,
        confidence=sequence.confidence,
        bridged=bridged,
        markers=correction,
    )


def _count_by_kind(findings: list[dict[str, Any]]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for finding in findings:
        kind = str(finding.get("kind", "other"))
        counts[kind] = counts.get(kind, 0) + 1
    return counts


def analyze(
    take: Take,
    options: AnalysisOptions,
    progress: ProgressCallback | None = None,
    catalog: ModelCatalog | None = None,
) -> AnalysisResult:
    """Analyse a take.

    Parameters
    ----------
    take : Motion or KeypointSequence
        The take as read.
    options : AnalysisOptions
        What to run.
    progress : callable, optional
        Called as ``progress(percent, step)`` with percent in 0–100.
    catalog : ModelCatalog, optional
        Where ``options.limits_model`` is looked up (the server's and the batch's: the data
        folder's registered models too); None offers the shipped models only.

    Returns
    -------
    AnalysisResult
    """
    report_progress = progress or _no_progress
    if isinstance(take, Motion):
        result = _analyze_motion(take, options, report_progress, catalog)
    else:
        result = _analyze_keypoints(take, options, report_progress)
    report_progress(95, "analysis finished")
    return result
