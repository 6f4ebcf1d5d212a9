"""The pipeline's steps: each calls one algorithm entry point and normalises its output.

* twist — :func:`mocapqa.twist.analysis.analyze_twist`; a rig on which no limb chain is found
  (no roles by name or mapping) reports ``"no_roles"`` naming what is missing, so an
  unchecked take is never read as a clean one
* limits — the run's model from :class:`mocapqa.limits.catalog.ModelCatalog` and
  :func:`mocapqa.limits.analysis.check_limits`; a rig the model does not cover reports
  ``"no_model"`` ("no model for this rig") instead of failing the run
* filters — :func:`mocapqa.filters.apply.filter_keypoints` and
  :func:`~mocapqa.filters.apply.filter_motion`
* markers — :func:`mocapqa.pipeline.marker_step.run_markers` (checks, swap repair, gap fill of
  a marker take)

Every step returns a :class:`StepOutcome` whose ``findings`` share one shape
(``kind, joint, start_frame, end_frame, value, unit, confidence``; frames inclusive) and whose
``plot`` holds the series the UI plots on every frame, with the frames a plot must keep; the
run samples every step's series on one frame axis chosen from all of them
(:func:`mocapqa.core.decimate.peak_frames`). Angles are in degrees.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, true_runs
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion, Skeleton
from mocapqa.core.rig import find_roles
from mocapqa.errors import LimitsFileError, OptionError
from mocapqa.filters.apply import filter_keypoints, filter_motion
from mocapqa.limits.analysis import check_limits
from mocapqa.limits.catalog import DEFAULT_MODEL, ModelCatalog
from mocapqa.limits.model import LimitsModel
from mocapqa.pipeline.options import ParamValue
from mocapqa.twist.analysis import analyze_twist, interval_frames
from mocapqa.twist.choice import decision_readout
from mocapqa.twist.reviewer_prior import ReviewerPrior
from mocapqa.twist.spin import LimbSpin, find_limb_spins

if TYPE_CHECKING:
    from mocapqa.markers.repair import MarkerRepair

__all__ = [
    "STEP_STATES",
    "Plot",
    "StepOutcome",
    "run_filter_keypoints",
    "run_filter_motion",
    "run_limits",
    "run_twist",
    "true_runs",
    "violation_findings",
]


@dataclass(frozen=True, slots=True)
class Plot:
    """A step's plotted series, before the run chooses the frames it samples.

    Parameters
    ----------
    signals : ndarray, shape (F, S)
        Every plotted series on every frame (degrees or shares; NaN where missing).
    keep : ndarray of int, shape (K,)
        Frames the plot must keep (its findings' edges), most important first.
    at : callable
        ``at(frames)`` → the JSON-ready series sampled at ``frames`` (increasing, shape (N,)).
    """

    signals: FloatArray
    keep: IntArray
    at: Callable[[IntArray], dict[str, Any]]


STEP_STATES = ("done", "skipped", "no_model", "no_roles")
"""What became of a step: it ran; it was not asked for (or does not apply to the take's kind);
the limits step found no model for the rig; the twist step found no limb chain on it."""


@dataclass(frozen=True, slots=True)
class StepOutcome:
    """What one step produced.

    Parameters
    ----------
    state : str
        One of :data:`STEP_STATES`.
    message : str
        One line for the UI.
    findings : list of dict
        Normalised findings.
    plot : Plot, optional
        Plotted series on every frame, sampled once the run's frames are chosen.
    motion : Motion, optional
        A corrected motion, when the step makes one.
    keypoints : KeypointSequence, optional
        Filtered keypoints, when the step makes them.
    bridged : ndarray of bool, shape (F, K), optional
        Samples the keypoint filter bridged (no valid input), when the step filters keypoints.
    markers : MarkerRepair, optional
        The swaps repaired and the gaps filled, when the step checks markers.
    """

    state: str
    message: str = ""
    findings: list[dict[str, Any]] = field(default_factory=list)
    plot: Plot | None = None
    motion: Motion | None = None
    keypoints: KeypointSequence | None = None
    bridged: BoolArray | None = None
    markers: MarkerRepair | None = None


def _finding_edges(findings: list[dict[str, Any]]) -> IntArray:
    """Every finding's first frame, then every last frame, the largest ``value`` first."""
    ordered = sorted(findings, key=lambda f: -abs(float(f["value"])))
    starts = [int(f["start_frame"]) for f in ordered]
    return np.asarray(starts + [int(f["end_frame"]) for f in ordered], dtype=np.intp)


def run_twist(
    motion: Motion,
    method: str,
    mapping: dict[str, str] | None = None,
    apply: str = "confident",
    prior: ReviewerPrior | None = None,
) -> StepOutcome:
    """Detect twist errors on every limb chain and remove those ``apply`` chooses (``prior``:
    a shoot's reviewer prior, :mod:`mocapqa.twist.reviewer_prior`).

    ``mapping`` (role key → joint name) overrides the roles found on the rig; the message names
    the roles that were not found, whose chains are not checked. Every interval is a finding,
    with its calibrated confidence, its id (for ``apply``) and whether the corrected take has it
    removed. Limb spins and flips (:func:`mocapqa.twist.spin.find_limb_spins`) are findings of
    kind ``spin``, never applied.
    """
    try:
        analysis = analyze_twist(motion, method=method, mapping=mapping, apply=apply, prior=prior)
    except OptionError as error:
        if error.field != "apply":
            raise
        raise OptionError("twist_apply", error.message) from error
    rig = find_roles(motion.skeleton, mapping)
    missing = rig.unmapped
    if not analysis.chains:
        return StepOutcome(
            "no_roles",
            f"no limb chain found, nothing checked (roles not found: {', '.join(missing)}); "
            "name the joints with a mapping (docs/rigs.md)",
        )
    spins = find_limb_spins(motion, rig)
    findings = [
        {
            "kind": "twist",
            "joint": interval.joint,
            "start_frame": int(interval.start_frame),
            "end_frame": int(interval.end_frame),
            "value": round(float(interval.offset_deg), 3),
            "unit": "deg",
            "confidence": round(float(interval.confidence), 3),
            "id": interval.id,
            "applied": interval.applied,
            "readout": decision_readout(dict(interval.evidence)),
        }
        for interval in analysis.intervals
    ] + [spin_finding(spin) for spin in spins]
    plot = Plot(
        analysis.plotted_deg(),
        analysis.step_frames(),
        lambda frames: analysis.to_json(frames=frames),
    )
    unchecked = f"; roles not found, not checked: {', '.join(missing)}" if missing else ""
    return StepOutcome(
        "done",
        f"{len(analysis.intervals)} twist interval(s) on {len(analysis.chains)} chain(s), "
        f"{sum(i.applied for i in analysis.intervals)} applied ({analysis.apply}); "
        f"{len(spins)} limb spin(s) reported, not corrected{unchecked}",
        findings,
        plot,
        analysis.refined,
    )


def spin_finding(spin: LimbSpin) -> dict[str, Any]:
    """The finding of a limb spin or flip (:mod:`mocapqa.twist.spin`): reported, never applied;
    ``value`` is the summed roll of a spin or the largest step of a flip, degrees."""
    return {
        "kind": "spin",
        "joint": spin.joint,
        "start_frame": spin.start_frame,
        "end_frame": spin.end_frame,
        "value": round(spin.value_deg, 3),
        "unit": "deg",
        "confidence": None,
        "shape": spin.shape,
        "readout": spin.readout(),
    }


def violation_findings(
    valid: BoolArray,
    score_deg: FloatArray,
    joints: list[str],
    readout: Callable[[int, int], str] | None = None,
) -> list[dict[str, Any]]:
    """One finding per joint and run of consecutive frames outside the limits.

    Parameters
    ----------
    valid : ndarray of bool, shape (F, J)
        Inside the limits.
    score_deg : ndarray, shape (F, J)
        Distance outside the limits, degrees.
    joints : list of str
        Joint names of the J columns.
    readout : callable, optional
        ``(frame, column) -> str``, the anatomical read-out
        (:meth:`mocapqa.limits.analysis.LimitsReport.readout`); each finding then carries the
        one of its worst frame as ``readout``.
    """
    findings: list[dict[str, Any]] = []
    for j, joint in enumerate(joints):
        bad = ~valid[:, j]
        if not bad.any():
            continue
        for start, last in true_runs(bad).tolist():
            stop = last + 1
            finding: dict[str, Any] = {
                "kind": "limits",
                "joint": joint,
                "start_frame": int(start),
                "end_frame": int(stop - 1),
                "value": round(float(score_deg[start:stop, j].max()), 3),
                "unit": "deg",
                "confidence": None,
            }
            if readout is not None:
                worst = int(start + np.argmax(score_deg[start:stop, j]))
                finding["readout"] = readout(worst, j)
            findings.append(finding)
    return findings


RigKey = tuple[tuple[str, ...], bytes, bytes, tuple[tuple[str, str], ...]]
_RIGS: dict[RigKey, Skeleton] = {}
_SHIPPED = ModelCatalog()


@functools.lru_cache(maxsize=16)
def _default_for_rig(key: RigKey) -> LimitsModel | str:
    # The default choice reads only shipped, read-only package data: decide it once per rig
    # layout (names, parents and rest offsets, which decide the fingerprint) and mapping, not
    # once per run.
    try:
        return _SHIPPED.load(DEFAULT_MODEL, _RIGS[key], dict(key[3]))
    except LimitsFileError as e:
        return str(e)


def run_limits(
    motion: Motion,
    mapping: dict[str, str] | None = None,
    model_name: str = DEFAULT_MODEL,
    catalog: ModelCatalog | None = None,
    twist_findings: list[dict[str, Any]] | None = None,
) -> StepOutcome:
    """Check joint limits with the model ``model_name`` of ``catalog`` (the shipped models
    when None; the default choice is decided once per rig layout).

    ``mapping`` (role key → joint name) decides the roles the canonical model checks; the
    message counts the joints that are not checked and ``summary.not_checked`` names them.
    ``twist_findings`` (the twist step's findings) keep the frames of their intervals from
    setting the canonical frames of a rig the model has not seen.

    Raises
    ------
    OptionError
        ``model_name`` is not a model of the catalog.
    """
    skeleton = motion.skeleton
    model: LimitsModel | str
    if model_name == DEFAULT_MODEL:
        named = tuple(sorted((mapping or {}).items()))
        key = (skeleton.names, skeleton.parents.tobytes(), skeleton.offsets.tobytes(), named)
        _RIGS.setdefault(key, skeleton)
        model = _default_for_rig(key)
    else:
        try:
            model = (catalog or _SHIPPED).load(model_name, skeleton, mapping)
        except LimitsFileError as e:
            model = str(e)
    if isinstance(model, str):
        return StepOutcome("no_model", f"no model for this rig ({model_name}: {model})")
    ignore = None
    if twist_findings:
        ignore = interval_frames(
            motion.skeleton.names,
            motion.n_frames,
            [(f["joint"], f["start_frame"], f["end_frame"]) for f in twist_findings
             if f["kind"] == "twist"],
        )  # fmt: skip
    report = check_limits(motion, model, mapping=mapping, ignore=ignore)
    joints = list(report.joint_names)
    findings = violation_findings(report.valid, report.score_deg, joints, report.readout)
    heat = np.where(report.valid, 0.0, report.score_deg)
    summary = report.to_json(max_points=1)
    for joint in summary["joints"]:
        joint.pop("frames", None)  # the heat map carries the per-frame values

    def at(frames: IntArray) -> dict[str, Any]:
        return {
            "joints": joints,
            "frames": frames.tolist(),
            "score_deg": np.round(heat[frames].T, 2).tolist(),
            # Hover text of the heat map: the anatomical read-out of each flagged cell.
            "readout": [[report.readout(int(f), j) for f in frames] for j in range(len(joints))],
            "summary": summary,
        }

    return StepOutcome(
        "done",
        f"{len(findings)} violation interval(s), model {model_name} ({report.rig_family}, "
        f"{report.framing}); "
        f"{len(report.not_checked)} joint(s) not checked (listed in summary.not_checked)",
        findings,
        Plot(heat, _finding_edges(findings), at),
    )


def run_filter_motion(motion: Motion, method: str, params: dict[str, ParamValue]) -> StepOutcome:
    """Filter a (corrected) motion's rotations and root translation."""
    filtered = filter_motion(motion, method, dict(params))
    return StepOutcome("done", f"filtered with {method}", motion=filtered)


def run_filter_keypoints(
    sequence: KeypointSequence,
    method: str,
    preset: str | None,
    params: dict[str, ParamValue],
) -> StepOutcome:
    """Filter keypoints; the series holds the filter weight timeline (mean over keypoints)."""
    result = filter_keypoints(sequence, method, preset or "default", dict(params))
    n_frames = sequence.n_frames
    n_keypoints = sequence.n_keypoints
    shares = np.zeros((n_frames, n_keypoints, 0)) if result.weights is None else result.weights
    # Plotted: the mean of each weight over the keypoints, then each keypoint's weights.
    mean = np.nan_to_num(shares).mean(axis=1)
    per_keypoint = shares.reshape(n_frames, n_keypoints * shares.shape[2])
    signals = np.concatenate([mean, per_keypoint], axis=1)

    def at(frames: IntArray) -> dict[str, Any]:
        sampled = np.nan_to_num(shares[frames])
        return {
            name: {
                "mean": np.round(mean[frames, i], 4).tolist(),
                "per_keypoint": np.round(sampled[:, :, i].T, 3).tolist(),
            }
            for i, name in enumerate(result.weight_names)
        }

    detail = result.to_json(max_points=1)
    for key in ("weights", "weights_mean", "timeline_frames"):
        detail.pop(key, None)
    bridged = int(result.bridged.sum())
    # Frames where any keypoint was bridged (no valid input), as [first, last] runs.
    runs = true_runs(np.any(result.bridged, axis=1))
    series = {
        "method": method,
        "names": list(sequence.names),
        "length_unit": sequence.length_unit,
        "summary": detail,
        "bridged_runs": runs.tolist(),
    }
    return StepOutcome(
        "done",
        f"filtered with {method} ({bridged} bridged samples)",
        [],
        Plot(
            signals,
            runs.reshape(-1),
            lambda frames: {**series, "weights": at(frames) if result.weights is not None else {}},
        ),
        keypoints=result.sequence,
        bridged=result.bridged,
    )
