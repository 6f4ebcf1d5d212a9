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
A motion take's analysis is here, a keypoint take's in
:mod:`mocapqa.pipeline.keypoint_analysis`; what both use (the result type, progress, the feet
check and its locks, the report's summary, steps and series) in
:mod:`mocapqa.pipeline.analysis_parts`.
"""

from __future__ import annotations

from typing import Any

from mocapqa import __version__
from mocapqa.core.motion import Motion
from mocapqa.core.rig import RigMap, find_roles
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.limits.catalog import DEFAULT_MODEL, ModelCatalog
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
from mocapqa.pipeline.frames import motion_pose, rigid_bones
from mocapqa.pipeline.keypoint_analysis import analyze_keypoints
from mocapqa.pipeline.loading import Take
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.pipeline.step_log import StepLog, requested
from mocapqa.pipeline.steps import run_filter_motion, run_limits, run_twist
from mocapqa.twist.reviewer_prior import ReviewerPrior

__all__ = ["AnalysisResult", "ProgressCallback", "analyze", "series_json"]


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

    feet_step(motion, options, progress, 65, steps)
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
    corrected = feet_locks(motion, corrected, options, progress, steps)
    steps.skip("markers", "BVH takes have joints, not markers")

    progress(85, "forward kinematics (corrected)")
    with steps.timed("fk_corrected_s"):
        _, _, corrected_points, corrected_rotations = motion_pose(corrected)
    with steps.timed("series_s"):
        series = series_json(steps.plotted, motion.n_frames, motion.fps, options.max_points)
    report = {
        "kind": "motion",
        "version": __version__,
        "summary": report_summary(motion, _motion_facts(motion, rig), steps.findings),
        "options": options.to_json(),
        "steps": steps_json(steps.outcomes),
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
    report_progress = progress or no_progress
    if isinstance(take, Motion):
        result = _analyze_motion(take, options, report_progress, catalog, prior)
    else:
        result = analyze_keypoints(take, options, report_progress)
    report_progress(95, "analysis finished")
    return result
