"""Findings (flagged intervals) read from the analyses' JSON outputs.

Conventions
-----------
A finding is a dict ``{"kind", "joint", "start_frame", "end_frame", ...}`` with inclusive,
0-based frames, plus ``offset_deg``, ``confidence`` and (when the input says) ``applied`` for
twist intervals (whether the corrected take removes it; a contact sheet shows no corrected pose
for one not applied) or ``violation_deg`` (largest distance outside the limits) for limit runs.
Limit runs are the maximal stretches of consecutive listed frames marked invalid; when the
limits JSON was decimated (``max_points``) a run covers the listed frames it spans. Inputs are the
``to_json()`` dicts of :class:`mocapqa.twist.analysis.TwistAnalysis` and
:class:`mocapqa.limits.analysis.LimitsReport`, or the pipeline's sampled limits heat map
(``joints``, ``frames``, ``score_deg`` as joints × frames); unknown keys are ignored. The
pipeline's own findings (``value`` and ``unit``) are mapped to the same keys by
:func:`normalise_findings`. A limit finding may carry ``readout``, the anatomical read-out of
its worst frame ("right knee hyperextended 14°"), when the input has one.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["limit_findings", "normalise_findings", "sheet_findings", "twist_findings"]


def twist_findings(twist: Mapping[str, Any] | None) -> list[dict[str, Any]]:
    """Twist intervals as findings, in the analysis' order (empty for None)."""
    if not twist:
        return []
    found = []
    for record in twist.get("intervals", []):
        finding = {
            "kind": "twist",
            "joint": str(record.get("joint")),
            "start_frame": int(record.get("start_frame", 0)),
            "end_frame": int(record.get("end_frame", 0)),
            "offset_deg": float(record.get("offset_deg", 0.0)),
            "confidence": float(record.get("confidence", 0.0)),
        }
        if record.get("applied") is not None:
            finding["applied"] = bool(record["applied"])
        found.append(finding)
    return found


def limit_findings(limits: Mapping[str, Any] | None, min_frames: int = 1) -> list[dict[str, Any]]:
    """Runs of frames outside the joint limits, per joint, ordered by joint then frame.

    Parameters
    ----------
    limits : mapping or None
        A limits report's ``to_json()``.
    min_frames : int
        Shortest run reported, in listed frames.
    """
    if not limits:
        return []
    found = []
    if "score_deg" in limits and limits.get("joints") and isinstance(limits["joints"][0], str):
        frames = np.asarray(limits.get("frames", []), dtype=np.int64)
        heat = np.asarray(limits["score_deg"], dtype=np.float64).reshape(len(limits["joints"]), -1)
        texts = limits.get("readout") or [[""] * heat.shape[1] for _ in limits["joints"]]
        limits = {
            "joints": [
                {
                    "name": name,
                    "frames": {
                        "frame": frames,
                        "valid": heat[j] <= 0,
                        "score_deg": heat[j],
                        "readout": texts[j],
                    },
                }
                for j, name in enumerate(limits["joints"])
            ]
        }
    for joint in limits.get("joints", []):
        series = joint.get("frames", {})
        frames = np.asarray(series.get("frame", []), dtype=np.int64)
        valid = np.asarray(series.get("valid", []), dtype=bool)
        scores = np.asarray(series.get("score_deg", np.zeros(len(frames))), dtype=np.float64)
        if len(frames) == 0 or len(valid) != len(frames):
            continue
        invalid = np.concatenate([[False], ~valid, [False]])
        edges = np.flatnonzero(np.diff(invalid.astype(np.int8)))
        for start, stop in zip(edges[::2], edges[1::2], strict=True):
            if stop - start < min_frames:
                continue
            finding = {
                "kind": "limits",
                "joint": str(joint.get("name")),
                "start_frame": int(frames[start]),
                "end_frame": int(frames[stop - 1]),
                "violation_deg": float(np.max(scores[start:stop])) if len(scores) else 0.0,
            }
            texts = series.get("readout")
            if texts is not None and len(texts) == len(frames) and len(scores):
                finding["readout"] = str(texts[start + int(np.argmax(scores[start:stop]))])
            found.append(finding)
    return found


def normalise_findings(findings: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Pipeline findings (``kind, joint, start_frame, end_frame, value, unit, confidence``)
    in this module's keys: ``offset_deg`` for twist intervals and limb spins (signed rolls),
    ``violation_deg`` for limits."""
    out = []
    for record in findings:
        item = dict(record)
        kind = str(item.get("kind", ""))
        if "value" in item and item["value"] is not None:
            key = "offset_deg" if kind in ("twist", "spin") else "violation_deg"
            item.setdefault(key, float(item["value"]))
        item["kind"] = kind
        item["start_frame"] = int(item.get("start_frame", 0))
        item["end_frame"] = int(item.get("end_frame", item["start_frame"]))
        out.append(item)
    return out


def sheet_findings(findings: list[dict[str, Any]], max_tiles: int = 8) -> list[dict[str, Any]]:
    """The findings a contact sheet shows: twist intervals first, then the largest limit
    violations, at most ``max_tiles`` (normalised as by :func:`normalise_findings`). Limb
    spins are left out: a sheet compares raw and corrected poses, and a spin is never
    corrected (the findings table lists them)."""
    normalised = normalise_findings(findings)
    twists = [f for f in normalised if f["kind"] == "twist"]
    others = sorted(
        (f for f in normalised if f["kind"] not in ("twist", "spin")),
        key=lambda f: -float(f.get("violation_deg", 0)),
    )
    return [*twists, *others][:max_tiles]
