"""The QA summary of one analysed take and its QA score (defined in ``docs/qa-summary.md``).

One flat, JSON-ready dict per take, the same for the batch table, the API and the UI:

* ``n_frames``, ``duration_s``, ``rig`` (limits rig family for BVH, ``"keypoints"`` otherwise)
* ``twist_intervals`` and ``corrected_joint_frames`` (sum of the intervals' lengths)
* ``violation_share`` — share of frames where at least one joint is outside its limits, and
  ``worst_joint`` — the joint outside its limits in the most frames (None when none is)
* ``joint_violations`` — per joint, share of frames outside the limits (joints with any)
* ``filter_residual_mm`` — RMS distance between raw and filtered keypoints, mm (keypoint takes
  in a metric unit; None otherwise)
* ``missing_share`` — share of missing keypoint samples (0 for BVH takes); of a marker take
  the markers step checked, the share still missing after its fills
* ``marker_gaps``, ``gaps_filled``, ``filled_share`` (filled samples over frames × markers),
  ``marker_swaps``, ``swaps_repaired``, ``marker_spikes`` and ``marker_label_problems``
  (static, absent, unlabelled and duplicate-labelled markers) — marker takes the markers step
  checked (None otherwise); in the run's summary and the report, not columns of the shoot
  table (its score counts them)
* ``foot_contacts``, ``foot_skates``, ``foot_penetrations``, ``foot_floating`` and
  ``foot_jitter`` — the feet step's contacts and findings by kind, for takes it checked (None
  otherwise); in the run's summary and the report; the shoot table has the skate,
  penetration and floating counts (its score counts every kind)
* ``foot_worst_skate`` and ``foot_skate_unit`` — the largest skate finding's size and its unit
  (``"cm"``, or ``"% height"`` when the take's unit does not convert to cm), as the feet step
  reports it; None when the step did not run or found no skate
* ``foot_worst_skate_pct`` — the largest skate as % of the body height the feet check estimates
  from the leg length, whatever the take's unit (a ``"% height"`` finding's value, a cm
  finding's ``size_rel_height`` × 100): the one skate figure that compares across takes; None
  when no skate has it
* ``score`` — 0–100, see :func:`qa_score`; None for a motion take on which none of the twist,
  limits and feet checks ran (nothing was checked, so nothing can be called clean)

Checks that did not run leave their fields None; they then cost the score nothing.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from mocapqa.limits.rig import rig_family

if TYPE_CHECKING:  # the store reads SUMMARY_FIELDS without loading the analysis stack
    from mocapqa.pipeline.analyze import AnalysisResult

__all__ = [
    "FEET_FIELDS",
    "FEET_SIZE_FIELDS",
    "MARKER_FIELDS",
    "MM_PER_UNIT",
    "PCT_HEIGHT",
    "SCORE_TERMS",
    "SUMMARY_FIELDS",
    "qa_score",
    "qa_summary",
    "skate_pct_height",
]

MM_PER_UNIT = {"m": 1000.0, "cm": 10.0, "mm": 1.0}
"""Millimetres per length unit, for the units a residual can be given in mm."""

SCORE_TERMS: dict[str, tuple[float, float]] = {
    "twist_intervals": (0.30, 2.0),
    "corrected_share": (0.20, 0.01),
    "violation_share": (0.40, 0.05),
    "missing_share": (0.40, 0.05),
    "filter_residual_mm": (0.20, 20.0),
    "filled_share": (0.10, 0.05),
    "marker_swaps": (0.30, 1.0),
    "marker_spikes": (0.20, 5.0),
    "marker_label_problems": (0.20, 1.0),
    "foot_skates": (0.25, 2.0),
    "foot_penetrations": (0.15, 2.0),
    "foot_floating": (0.10, 2.0),
    "foot_jitter": (0.10, 3.0),
}
"""Per defect ``x``: weight ``w`` and half-effect value ``s`` of the factor ``1 − w·x/(x+s)``."""

SUMMARY_FIELDS = (
    "n_frames",
    "duration_s",
    "rig",
    "twist_intervals",
    "corrected_joint_frames",
    "limb_spins",
    "violation_share",
    "worst_joint",
    "filter_residual_mm",
    "missing_share",
    "score",
)
"""The summary's scalar columns, in table order (``joint_violations`` is the per-joint map)."""
MARKER_FIELDS = (
    "marker_gaps",
    "gaps_filled",
    "filled_share",
    "marker_swaps",
    "swaps_repaired",
    "marker_spikes",
    "marker_label_problems",
)
"""The summary's marker counts (marker takes; None for others)."""
FEET_FIELDS = ("foot_contacts", "foot_skates", "foot_penetrations", "foot_floating", "foot_jitter")
"""The summary's feet counts (takes the feet step checked; None for others)."""
FEET_SIZE_FIELDS = ("foot_worst_skate", "foot_skate_unit", "foot_worst_skate_pct")
"""The summary's largest skate, its unit and its share of the body height in % (takes with a
skate finding; None for others)."""
PCT_HEIGHT = "% height"
"""The unit of a feet size given as % of the body height estimated from the leg length."""
_FEET_KINDS = {
    "skate": "foot_skates",
    "penetration": "foot_penetrations",
    "floating": "foot_floating",
    "jitter": "foot_jitter",
}
_LABEL_KINDS = ("static marker", "absent marker", "unlabelled marker", "duplicate label")


def qa_score(defects: dict[str, float | None]) -> float:
    """The QA score, 0–100 (100: no defect found), rounded to 0.1.

    ``score = 100 · Π_k (1 − w_k · x_k / (x_k + s_k))`` over the defects of
    :data:`SCORE_TERMS`; a missing (None) or zero defect contributes a factor 1. Every factor
    lies in ``(1 − w_k, 1]`` and decreases strictly as its defect grows, so the score is
    monotone (non-increasing) in each defect and never below ``100 · Π (1 − w_k)``.

    Parameters
    ----------
    defects : dict
        Keys of :data:`SCORE_TERMS`; values ≥ 0 or None. ``corrected_share`` is corrected
        joint-frames over ``frames × joints``.
    """
    score = 100.0
    for name, (weight, half) in SCORE_TERMS.items():
        value = defects.get(name)
        if value is None or not math.isfinite(value) or value <= 0:
            continue
        score *= 1.0 - weight * value / (value + half)
    return round(score, 1)


def _union_frames(findings: list[dict[str, Any]], n_frames: int) -> int:
    flagged = np.zeros(n_frames + 1, dtype=np.int32)
    for finding in findings:
        start = max(0, int(finding["start_frame"]))
        stop = min(n_frames, int(finding["end_frame"]) + 1)
        if stop > start:
            flagged[start] += 1
            flagged[stop] -= 1
    return int(np.count_nonzero(np.cumsum(flagged)[:n_frames]))


def _marker_counts(findings: list[dict[str, Any]], samples: int) -> dict[str, Any]:
    """The marker fields of the summary from the markers step's findings."""
    count = {kind: 0 for kind in ("gap", "gap not filled", "swap", "spike")}
    filled = repaired = labels = 0
    for finding in findings:
        kind = finding["kind"]
        if kind in count:
            count[kind] += 1
        if kind == "gap":
            filled += int(finding["end_frame"]) - int(finding["start_frame"]) + 1
        repaired += kind == "swap" and bool(finding.get("applied"))
        labels += kind in _LABEL_KINDS
    return {
        "marker_gaps": count["gap"] + count["gap not filled"],
        "gaps_filled": count["gap"],
        "filled_share": round(filled / max(samples, 1), 6),
        "marker_swaps": count["swap"],
        "swaps_repaired": repaired,
        "marker_spikes": count["spike"],
        "marker_label_problems": labels,
    }


def _feet_counts(findings: list[dict[str, Any]], contacts: int) -> dict[str, int]:
    """The feet fields of the summary from the feet step's findings and its contacts."""
    counts = dict.fromkeys(FEET_FIELDS, 0)
    counts["foot_contacts"] = contacts
    for finding in findings:
        field = _FEET_KINDS.get(finding["kind"])
        if field is not None and "foot" in finding:
            counts[field] += 1
    return counts


def skate_pct_height(finding: dict[str, Any]) -> float | None:
    """A skate finding's size in % of the body height the feet check estimates.

    Parameters
    ----------
    finding : dict
        A feet step finding: ``value`` in ``unit`` (``"cm"`` or :data:`PCT_HEIGHT`) and,
        when given, ``size_rel_height`` (the size over the estimated body height, a ratio).

    Returns
    -------
    float or None
        % of the body height, rounded to 0.001; None when the finding has no size, or is in
        cm without ``size_rel_height``.
    """
    rel = finding.get("size_rel_height")
    if rel is not None:
        return round(100.0 * float(rel), 3)
    value = finding.get("value")
    return None if value is None or finding.get("unit") != PCT_HEIGHT else float(value)


def _worst_skate(findings: list[dict[str, Any]]) -> dict[str, Any]:
    """The largest skate finding's size and unit, and the largest in % of the body height
    (:data:`FEET_SIZE_FIELDS`; None when none has a size)."""
    skates = [f for f in findings if f["kind"] == "skate" and "foot" in f]
    sizes = [(float(f["value"]), str(f["unit"])) for f in skates if f.get("value") is not None]
    if not sizes:
        return dict.fromkeys(FEET_SIZE_FIELDS)
    value, unit = max(sizes, key=lambda size: size[0])
    shares = [p for p in map(skate_pct_height, skates) if p is not None]
    share = max(shares) if shares else None
    return {"foot_worst_skate": value, "foot_skate_unit": unit, "foot_worst_skate_pct": share}


def _residual_mm(result: AnalysisResult, unit: str) -> float | None:
    scale = MM_PER_UNIT.get(unit)
    if scale is None:
        return None
    raw = np.asarray(result.raw_points, dtype=np.float64)
    filtered = np.asarray(result.corrected_points, dtype=np.float64)
    both = np.isfinite(raw).all(axis=-1) & np.isfinite(filtered).all(axis=-1)
    if not both.any():
        return None
    distance = np.linalg.norm(raw[both] - filtered[both], axis=-1)
    return round(float(np.sqrt(np.mean(distance**2))) * scale, 4)


def _limits_fields(
    findings: list[dict[str, Any]], n_frames: int
) -> tuple[float, str | None, dict[str, float]]:
    """The limits fields of the summary from the findings of a limits check that ran.

    Returns
    -------
    violation_share : float
        Share of frames where at least one joint is outside its limits.
    worst_joint : str or None
        The joint outside its limits in the most frames (None when none is).
    joint_violations : dict of str to float
        Per joint, share of frames outside the limits (joints with any).
    """
    limit_findings = [f for f in findings if f["kind"] == "limits"]
    violation_share = round(_union_frames(limit_findings, n_frames) / max(n_frames, 1), 6)
    per_joint: dict[str, int] = {}
    for finding in limit_findings:
        length = int(finding["end_frame"]) - int(finding["start_frame"]) + 1
        per_joint[finding["joint"]] = per_joint.get(finding["joint"], 0) + length
    joint_violations = {j: round(n / max(n_frames, 1), 6) for j, n in per_joint.items()}
    worst_joint = max(per_joint, key=lambda j: (per_joint[j], j)) if per_joint else None
    return violation_share, worst_joint, joint_violations


def _score_terms(
    summary: dict[str, Any],
    twist_count: int | None,
    corrected_share: float | None,
    markers: dict[str, Any] | None,
    feet: dict[str, int] | None,
) -> dict[str, float | None]:
    """The measures :func:`qa_score` weighs, from the summary's fields (None: not checked)."""
    return {
        "twist_intervals": None if twist_count is None else float(twist_count),
        "corrected_share": corrected_share,
        "violation_share": summary["violation_share"],
        "missing_share": summary["missing_share"],
        "filter_residual_mm": summary["filter_residual_mm"],
        **{k: float(markers[k]) for k in MARKER_FIELDS if k in SCORE_TERMS and markers},
        **{k: float(feet[k]) for k in FEET_FIELDS if k in SCORE_TERMS and feet},
    }


def qa_summary(result: AnalysisResult) -> dict[str, Any]:
    """The QA summary of an analysis (fields in the module docstring).

    Parameters
    ----------
    result : AnalysisResult
        As returned by :func:`mocapqa.pipeline.analyze.analyze`.

    Returns
    -------
    dict
        JSON-ready; shares in [0, 1], residual in mm, score in [0, 100].
    """
    report = result.report
    info = report["summary"]
    steps = report["steps"]
    findings = report["findings"]
    n_frames = int(info["n_frames"])
    motion = report["kind"] == "motion"
    twist_ran = motion and steps["twist"]["state"] == "done"
    limits_ran = motion and steps["limits"]["state"] == "done"
    filter_ran = not motion and steps["filter"]["state"] == "done"
    markers_ran = steps.get("markers", {}).get("state") == "done"
    feet_ran = steps.get("feet", {}).get("state") == "done"

    twist = [f for f in findings if f["kind"] == "twist"]
    spins = [f for f in findings if f["kind"] == "spin"]
    corrected = sum(int(f["end_frame"]) - int(f["start_frame"]) + 1 for f in twist)
    n_joints = int(info.get("n_joints") or info.get("n_keypoints") or 1)
    rig = "keypoints"
    if result.corrected_motion is not None:
        rig = rig_family(result.corrected_motion.skeleton)
    violation_share, worst_joint, joint_violations = (
        _limits_fields(findings, n_frames) if limits_ran else (None, None, {})
    )
    residual = _residual_mm(result, str(info.get("length_unit"))) if filter_ran else None
    missing = 0.0 if motion else round(float(info.get("missing_fraction") or 0.0), 6)
    markers = _marker_counts(findings, n_frames * n_joints) if markers_ran else None
    if markers is not None:  # the fills' samples are no longer missing
        missing = round(max(0.0, missing - float(markers["filled_share"])), 6)
    feet = None
    if feet_ran:
        feet_series = (report.get("series") or {}).get("feet") or {}
        feet = _feet_counts(findings, len(feet_series.get("contacts") or ()))
    summary: dict[str, Any] = {
        "n_frames": n_frames,
        "duration_s": round(float(info["duration_s"]), 4),
        "rig": rig,
        "twist_intervals": len(twist) if twist_ran else None,
        "corrected_joint_frames": corrected if twist_ran else None,
        "limb_spins": len(spins) if twist_ran else None,
        "violation_share": violation_share,
        "worst_joint": worst_joint,
        "filter_residual_mm": residual,
        "missing_share": missing,
        "joint_violations": joint_violations,
        **(markers or dict.fromkeys(MARKER_FIELDS)),
        **(feet or dict.fromkeys(FEET_FIELDS)),
        **(_worst_skate(findings) if feet_ran else dict.fromkeys(FEET_SIZE_FIELDS)),
    }
    # A motion take on which none of the twist, limits and feet checks ran (a rig whose roles
    # were not found, a run of the filter only) has no score: 100 would read as "checked and
    # clean".
    checked = twist_ran or limits_ran or feet_ran or not motion
    corrected_share = corrected / max(n_frames * n_joints, 1) if twist_ran else None
    terms = _score_terms(summary, len(twist) if twist_ran else None, corrected_share, markers, feet)
    summary["score"] = qa_score(terms) if checked else None
    return summary
