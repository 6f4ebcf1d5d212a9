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

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from mocapqa import __version__
from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.decimate import peak_frames
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.core.rig import RigMap, find_roles
from mocapqa.errors import InputError
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.limits.catalog import DEFAULT_MODEL, ModelCatalog
from mocapqa.markers.repair import MarkerRepair
from mocapqa.pipeline.feet_step import lock_run_feet, run_feet
from mocapqa.pipeline.frames import motion_pose, rigid_bones
from mocapqa.pipeline.loading import Take
from mocapqa.pipeline.marker_step import run_markers
from mocapqa.pipeline.options import DEFAULT_KEYPOINT_FILTER, AnalysisOptions, take_checks
from mocapqa.pipeline.step_log import StepLog, requested
from mocapqa.pipeline.steps import (
    StepOutcome,
    run_filter_keypoints,
    run_filter_motion,
    run_limits,
    run_twist,
)
from mocapqa.twist.reviewer_prior import ReviewerPrior

__all__ = ["AnalysisResult", "ProgressCallback", "analyze", "series_json"]

ProgressCallback = Callable[[int, str], None]
"""Called as ``progress(percent, step)`` with percent in 0–100."""

_Take = TypeVar("_Take", Motion, KeypointSequence)


@dataclass(frozen=True, slots=True)
class AnalysisResult:
    """Everything one run produces.

    Parameters
    ----------
    report : dict
        JSON-ready report (summary, steps, findings, series).
    corrected_motion : Motion, optional
        Twist-refined (and optionally filtered, then foot-locked) motion, for BVH takes.
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


def _feet_step(
    take: Motion | KeypointSequence,
    options: AnalysisOptions,
    progress: ProgressCallback,
    percent: int,
    steps: StepLog,
) -> None:
    """The feet check of the take as read (plotted only when it ran to the end)."""
    if not requested("feet", options, steps):
        return
    progress(percent, "feet and floor check")
    mapping = options.mapping if isinstance(take, Motion) else None
    with steps.timed("feet_s"):
        outcome = run_feet(take, mapping, options.feet_apply)
    steps.record("feet", outcome, plot=outcome.state == "done")


def _feet_locks(
    checked: _Take,
    target: _Take,
    options: AnalysisOptions,
    progress: ProgressCallback,
    steps: StepLog,
) -> _Take:
    """The corrected take with the foot contacts of the run's ``feet_apply`` locked, the last
    correction (nothing moves a planted foot after it); ``target`` itself when the choice is
    ``"none"`` or the feet step did not run to the end."""
    feet = steps.outcomes.get("feet")
    if options.feet_apply == "none" or feet is None or feet.state != "done":
        return target
    progress(80, "locking planted feet")
    with steps.timed("feet_lock_s"):
        locked = lock_run_feet(checked, target, options.feet_apply, options.mapping or None)
    if not isinstance(locked, type(target)):  # pragma: no cover - fix_feet keeps the kind
        raise TypeError(f"Expected a locked {type(target).__name__}, got {type(locked).__name__}")
    return locked


def _locked_repair(
    sequence: KeypointSequence,
    repair: MarkerRepair | None,
    options: AnalysisOptions,
    steps: StepLog,
) -> MarkerRepair | None:
    """The marker repair (what the run's corrected C3D is written from) with the run's foot
    locks pinned on its positions too, as on the filtered take (:func:`_feet_locks`)."""
    if repair is None:
        return None
    repaired = dataclasses.replace(sequence, positions=repair.positions)
    pinned = _feet_locks(sequence, repaired, options, _no_progress, steps)
    if pinned is repaired:
        return repair
    return dataclasses.replace(repair, positions=pinned.positions)


def _motion_checks(
    motion: Motion,
    options: AnalysisOptions,
    progress: ProgressCallback,
    catalog: ModelCatalog | None,
    steps: StepLog,
    prior: ReviewerPrior | None = None,
) -> Motion:
    """The twist (with the reviewer ``prior``), limits and feet checks of a motion take;
    returns it twist-refined."""
    corrected = motion
    if requested("twist", options, steps):
        progress(25, "twist analysis")
        with steps.timed("twist_s"):
            outcome = run_twist(
                motion, options.twist_method, options.mapping, options.twist_apply, prior
            )
        steps.record("twist", outcome)
        if outcome.motion is not None:
            corrected = outcome.motion

    if requested("limits", options, steps):
        progress(55, "joint-limit check")
        with steps.timed("limits_s"):
            twist_outcome = steps.outcomes.get("twist")
            outcome = run_limits(
                motion,
                options.mapping,
                options.limits_model or DEFAULT_MODEL,
                catalog,
                twist_findings=twist_outcome.findings if twist_outcome else None,
            )
        steps.record("limits", outcome)

    _feet_step(motion, options, progress, 65, steps)
    return corrected


def _motion_filter(
    corrected: Motion, options: AnalysisOptions, progress: ProgressCallback, steps: StepLog
) -> Motion:
    """The chosen filter over the corrected motion (neither plotted nor a source of
    findings); returns the filtered motion."""
    if "filter" not in options.checks or not options.filter_method:
        steps.skip("filter", "no filter chosen for motion takes")
        return corrected
    progress(75, "filtering the corrected motion")
    with steps.timed("filter_s"):
        outcome = run_filter_motion(corrected, options.filter_method, options.filter_params)
    steps.record("filter", outcome, plot=False, findings=False)
    return outcome.motion if outcome.motion is not None else corrected


def _summary(
    take: Motion | KeypointSequence, facts: dict[str, Any], findings: list[dict[str, Any]]
) -> dict[str, Any]:
    """The ``summary`` of a report: frames, rate and length, the take kind's ``facts``, then
    the findings counted."""
    return {
        "n_frames": take.n_frames,
        "fps": take.fps,
        "duration_s": take.n_frames / take.fps,
        **facts,
        "n_findings": len(findings),
        "findings_by_kind": _count_by_kind(findings),
    }


def _motion_facts(motion: Motion, rig: RigMap) -> dict[str, Any]:
    """What the summary of a motion take says of its skeleton and rig."""
    skeleton = motion.skeleton
    return {
        "n_joints": skeleton.n_joints,
        "length_unit": skeleton.length_unit,
        "root_translation": skeleton.root_translation,
        "bind_pose_frames": leading_bind_pose(motion.quats),
        "roles": {key: skeleton.names[j] for key, j in sorted(rig.roles.items())},
        "missing_roles": list(rig.unmapped),
    }


def _analyze_motion(
    motion: Motion,
    options: AnalysisOptions,
    progress: ProgressCallback,
    catalog: ModelCatalog | None,
    prior: ReviewerPrior | None = None,
) -> AnalysisResult:
    steps = StepLog()
    rig = find_roles(motion.skeleton, options.mapping)  # a bad mapping fails the run here
    progress(10, "forward kinematics (raw)")
    with steps.timed("fk_raw_s"):
        names, parents, raw_points, raw_rotations = motion_pose(motion)
    corrected = _motion_checks(motion, options, progress, catalog, steps, prior)
    corrected = _motion_filter(corrected, options, progress, steps)
    corrected = _feet_locks(motion, corrected, options, progress, steps)
    steps.skip("markers", "BVH takes have joints, not markers")

    progress(85, "forward kinematics (corrected)")
    with steps.timed("fk_corrected_s"):
        _, _, corrected_points, corrected_rotations = motion_pose(corrected)
    with steps.timed("series_s"):
        series = series_json(steps.plotted, motion.n_frames, motion.fps, options.max_points)
    report = {
        "kind": "motion",
        "version": __version__,
        "summary": _summary(motion, _motion_facts(motion, rig), steps.findings),
        "options": options.to_json(),
        "steps": _steps_json(steps.outcomes),
        "timings_s": {k: round(v, 4) for k, v in steps.timings.items()},
        "findings": steps.findings,
        "points": {
            "names": names,
            "parents": parents,
            "bones": rigid_bones(motion),
            "n_joints": motion.skeleton.n_joints,
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


def _analyze_keypoints(
    sequence: KeypointSequence, options: AnalysisOptions, progress: ProgressCallback
) -> AnalysisResult:
    if options.mapping:
        raise InputError("Expected the mapping option only for BVH takes, got a keypoint take")
    steps = StepLog()
    steps.skip("twist", "keypoint takes have no joint rotations")
    steps.skip("limits", "keypoint takes have no joint rotations")
    corrected = _keypoint_markers(sequence, options, progress, steps)
    _feet_step(sequence, options, progress, 25, steps)  # the feet of the take as read
    filtered = _keypoint_filter(corrected, options, progress, steps)
    filtered = _feet_locks(sequence, filtered, options, progress, steps)
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
        "summary": _summary(sequence, _keypoint_facts(sequence), steps.findings),
        "options": options.to_json(),
        "steps": _steps_json(steps.outcomes),
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
    prior: ReviewerPrior | None = None,
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
    prior : ReviewerPrior, optional
        The reviewer prior of the take's shoot for the twist step
        (:mod:`mocapqa.twist.reviewer_prior`); None: none.

    Returns
    -------
    AnalysisResult
    """
    report_progress = progress or _no_progress
    if isinstance(take, Motion):
        result = _analyze_motion(take, options, report_progress, catalog, prior)
    else:
        result = _analyze_keypoints(take, options, report_progress)
    report_progress(95, "analysis finished")
    return result
