"""What the motion and the keypoint analyses of a take share: the result type, progress, the
feet check and its locks, and the report's summary, steps and plotted series.

:func:`mocapqa.pipeline.analyze.analyze` runs one of the two (its own motion analysis, or
:func:`mocapqa.pipeline.keypoint_analysis.analyze_keypoints`) and returns an
:class:`AnalysisResult`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.decimate import peak_frames
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.markers.repair import MarkerRepair
from mocapqa.pipeline.feet_step import lock_run_feet, run_feet
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.pipeline.step_log import StepLog, requested
from mocapqa.pipeline.steps import StepOutcome

__all__ = [
    "AnalysisResult",
    "ProgressCallback",
    "feet_locks",
    "feet_step",
    "no_progress",
    "report_summary",
    "series_json",
    "steps_json",
]

ProgressCallback = Callable[[int, str], None]
"""Called as ``progress(percent, step)`` with percent in 0–100."""

_Take = TypeVar("_Take", Motion, KeypointSequence)
"""A take of either kind, the same in and out."""


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


def no_progress(percent: int, step: str) -> None:
    """A :data:`ProgressCallback` that reports nothing."""
    del percent, step


def steps_json(outcomes: dict[str, StepOutcome]) -> dict[str, dict[str, str]]:
    """The ``steps`` of a report: each step's ``state`` and ``message``, by name."""
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


def feet_step(
    take: Motion | KeypointSequence,
    options: AnalysisOptions,
    progress: ProgressCallback,
    percent: int,
    steps: StepLog,
) -> None:
    """The feet check of the take as read (plotted only when it ran to the end).

    Parameters
    ----------
    take : Motion or KeypointSequence
        The take as read.
    options : AnalysisOptions
        The run's options (``checks``, ``mapping``, ``feet_apply``).
    progress : ProgressCallback
    percent : int
        The progress reported on starting, 0–100.
    steps : StepLog
        Where the step's outcome and time are recorded.
    """
    if not requested("feet", options, steps):
        return
    progress(percent, "feet and floor check")
    mapping = options.mapping if isinstance(take, Motion) else None
    with steps.timed("feet_s"):
        outcome = run_feet(take, mapping, options.feet_apply)
    steps.record("feet", outcome, plot=outcome.state == "done")


def feet_locks(
    checked: _Take,
    target: _Take,
    options: AnalysisOptions,
    progress: ProgressCallback,
    steps: StepLog,
) -> _Take:
    """The corrected take with the foot contacts of the run's ``feet_apply`` locked, the last
    correction (nothing moves a planted foot after it).

    Parameters
    ----------
    checked : Motion or KeypointSequence
        The take the feet step checked (as read).
    target : Motion or KeypointSequence
        The corrected take, of the same kind.
    options : AnalysisOptions
    progress : ProgressCallback
    steps : StepLog
        Holds the feet step's outcome; the lock's time is recorded in it.

    Returns
    -------
    Motion or KeypointSequence
        Of ``target``'s kind; ``target`` itself when the choice is ``"none"`` or the feet step
        did not run to the end.
    """
    feet = steps.outcomes.get("feet")
    if options.feet_apply == "none" or feet is None or feet.state != "done":
        return target
    progress(80, "locking planted feet")
    with steps.timed("feet_lock_s"):
        locked = lock_run_feet(checked, target, options.feet_apply, options.mapping or None)
    if not isinstance(locked, type(target)):  # pragma: no cover - fix_feet keeps the kind
        raise TypeError(f"Expected a locked {type(target).__name__}, got {type(locked).__name__}")
    return locked


def report_summary(
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


def _count_by_kind(findings: list[dict[str, Any]]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for finding in findings:
        kind = str(finding.get("kind", "other"))
        counts[kind] = counts.get(kind, 0) + 1
    return counts
