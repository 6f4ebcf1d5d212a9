"""The run's feet step: contacts, foot skate, floor penetration, floating and jitter of a take.

:func:`run_feet` calls :func:`mocapqa.pipeline.feet.check_take_feet` (the check of
``mocapqa feet check``, docs/feet.md) on a BVH take, a keypoint take or a C3D/TRC marker take,
and turns its findings into the run's shape (``kind, joint, start_frame, end_frame, value,
unit, confidence``; frames 0-based and inclusive, counted in the take as read):

* ``kind`` — ``skate``, ``penetration``, ``floating`` or ``jitter``
  (:data:`FEET_FINDING_KINDS`);
* ``joint`` — the foot's rear point (a BVH's ankle joint, a heel or ankle keypoint or marker),
  ``foot`` — ``"left"`` or ``"right"``;
* ``value`` — the finding's size in cm (``unit`` ``"cm"``) when the take's length unit converts
  to cm; else (a BVH, which stores no unit; pixels) the size over the body height estimated
  from the leg length, in % (``unit`` ``"% height"``);
* ``confidence`` — that of the contact a skate lies in (None for the other kinds);
* ``applied`` — for a skate, whether the run's corrected take has its contact locked (the
  run's ``feet_apply`` choice, :func:`lock_run_feet`); None for the other kinds;
* ``id`` (``skate-left-120``, as ``mocapqa feet fix --apply`` takes), ``peak`` and, for a
  skate, ``speed_cm_s``; ``size_rel_height``, the size over the estimated body height (a
  ratio, whatever the unit: what compares across takes); a one-line ``readout`` for the
  findings list.

The step's plotted series (``series.feet`` of the report) hold the contacts
(``{"id", "foot", "start", "end", "confidence"}``), the up axis, the floor and its check (with
the fitted plane of a tilted floor: its height along the up axis at a horizontal point ``p``,
the two coordinates other than the up axis in increasing order, is ``floor + sign(up) *
(p - plane_origin) · plane_gradient``), and the counts of the check's summary: what the take
view's contact timeline and the 3D views' floor draw.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from mocapqa.core.arrays import IntArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.feet.fix import fix_feet
from mocapqa.feet.fix_choice import RUN_APPLY_CHOICES, add_ids, locked_findings
from mocapqa.feet.points import SIDES
from mocapqa.pipeline.feet import check_take_feet, feet_params_of, feet_report_json
from mocapqa.pipeline.steps import Plot, StepOutcome

__all__ = ["FEET_FINDING_KINDS", "feet_findings", "lock_run_feet", "run_feet"]

FEET_FINDING_KINDS = ("skate", "penetration", "floating", "jitter")
"""The kinds of finding the feet step reports."""

_WHAT = {
    "skate": "planted foot sliding",
    "penetration": "foot below the floor",
    "floating": "still foot above the floor",
    "jitter": "noise on a planted foot",
}


def feet_findings(
    check: Mapping[str, Any], joints: Mapping[str, str], locked: frozenset[str] = frozenset()
) -> list[dict[str, Any]]:
    """The feet step's findings (fields in the module docstring) from the feet check's JSON.

    Parameters
    ----------
    check : mapping
        :func:`mocapqa.pipeline.feet.feet_report_json` of the take, its findings with ``id``
        (and a skate's ``confidence``).
    joints : mapping of str to str
        Foot (``"left"``, ``"right"``) → the name of that foot's rear point.
    locked : frozenset of str
        Ids of the skate findings the run locks (:func:`mocapqa.feet.fix_choice.locked_findings`).
    """
    findings: list[dict[str, Any]] = []
    for item in check["findings"]:
        if item["size_cm"] is not None:
            value, unit = item["size_cm"], "cm"
        else:
            rel = item["size_rel_height"]
            value, unit = (None if rel is None else round(100.0 * rel, 3)), "% height"
        speed = item.get("speed_cm_s")
        size = "" if value is None else f"{value:g} {unit}"
        readout = f"{item['foot']} foot, {_WHAT[item['kind']]}" + (f" {size}" if size else "")
        if speed is not None:
            readout += f" at {speed:g} cm/s"
        skate = item["kind"] == "skate"
        if skate and item["id"] in locked:
            readout += "; locked in the corrected take"
        findings.append({
            "kind": item["kind"],
            "joint": joints[item["foot"]],
            "start_frame": item["start"],
            "end_frame": item["end"],
            "value": value,
            "unit": unit,
            "confidence": item.get("confidence"),
            "applied": (item["id"] in locked) if skate else None,
            "foot": item["foot"],
            "id": item["id"],
            "peak": item["peak"],
            "speed_cm_s": speed,
            "size_rel_height": item["size_rel_height"],
            "readout": readout,
        })  # fmt: skip
    return findings


def _check_ids(apply: str, findings: list[dict[str, Any]]) -> None:
    """Refuse ``feet_apply`` ids (not a named choice) that are not skate findings of the take.

    Raises
    ------
    InputError
        Naming ``feet_apply``, the ids not found and the take's skate findings.
    """
    if apply in RUN_APPLY_CHOICES:
        return
    skates = [str(f["id"]) for f in findings if f["kind"] == "skate"]
    missing = [key for key in apply.split(",") if key not in skates]
    if missing:
        listed = ", ".join(skates[:8]) + (", ..." if len(skates) > 8 else "")
        raise InputError(
            f"Expected feet_apply ids of skate findings of this take "
            f"({listed if skates else 'it has none'}), got {', '.join(missing[:4])}"
        )


def run_feet(
    take: Motion | KeypointSequence,
    mapping: Mapping[str, str] | None = None,
    apply: str = "none",
) -> StepOutcome:
    """Check the feet of a take.

    Parameters
    ----------
    take, mapping
        As in :func:`mocapqa.pipeline.feet.check_take_feet`.
    apply : str
        The run's ``feet_apply``: which skate findings are marked ``applied``
        (:func:`mocapqa.feet.fix_choice.locked_findings`); :func:`lock_run_feet` locks them.

    Returns
    -------
    StepOutcome
        ``"done"`` with the findings of the module docstring and the contacts in the plot's
        series; ``"skipped"`` with the reason when the take has no feet the check can use (a
        rig without legs, keypoints without hips, knees and ankles, markers without foot
        markers).

    Raises
    ------
    InputError
        For ``apply`` ids of findings or contacts the take does not have.
    """
    try:
        points, report, skipped = check_take_feet(
            take, mapping if isinstance(take, Motion) else None
        )
    except InputError as e:
        return StepOutcome("skipped", f"no feet to check: {e}")
    check = feet_report_json(points, report, skipped)
    add_ids(check, report.contacts, report.findings, skipped)
    _check_ids(apply, check["findings"])
    locked = frozenset(locked_findings(apply, report.contacts, report.findings, skipped))
    rear: dict[str, str] = {}
    for name, side in zip(points.names, points.sides, strict=True):
        rear.setdefault(side, name)  # each side's rear point (ankle or heel) comes first
    findings = feet_findings(check, rear, locked)
    series = {
        "contacts": check["contacts"],
        "up_axis": check["up_axis"],
        "floor": check["floor"],
        "floor_check": {
            k: check["floor_check"][k]
            for k in ("tilted", "moving", "tilt_deg", "plane_gradient", "plane_origin")
        },
        "length_unit": check["length_unit"],
        "sizes": check["sizes"],
        "checked_frames": check["checked_frames"],
        "feet": {side: rear.get(side) for side in SIDES},
        "summary": check["summary"],
    }
    edges: IntArray = np.asarray(
        [f["start_frame"] for f in findings] + [f["end_frame"] for f in findings], dtype=np.intp
    )
    counts = check["summary"]["findings"]
    contacts = check["summary"]["contacts"]
    return StepOutcome(
        "done",
        f"{contacts['left']} left and {contacts['right']} right contact(s), up {check['up_axis']}"
        f"{', floor tilted' if check['floor_check']['tilted'] else ''}; "
        + ", ".join(f"{counts[k]} {k}" for k in FEET_FINDING_KINDS),
        findings,
        Plot(np.empty((take.n_frames, 0)), edges, lambda frames: series),
    )


def lock_run_feet(
    checked: Motion | KeypointSequence,
    target: Motion | KeypointSequence,
    apply: str,
    mapping: Mapping[str, str] | None = None,
) -> Motion | KeypointSequence:
    """The run's corrected take with the foot contacts its ``feet_apply`` names locked, as
    ``mocapqa feet fix`` locks them (:func:`mocapqa.feet.fix.fix_feet`): a BVH take's legs by
    the two-bone leg IK (only the hips', knees' and ankles' rotations change), a keypoint or
    marker take's foot points pinned.

    Parameters
    ----------
    checked : Motion or KeypointSequence
        The take as read, the one the feet step checked (its contacts and ids).
    target : Motion or KeypointSequence
        The corrected take (twist intervals removed, markers repaired, filtered), of the same
        kind, rig and frames; the locks are solved on it, after every other correction.
    apply : str
        The run's ``feet_apply``; ``"none"`` returns ``target`` itself.
    mapping : mapping, optional
        The run's role mapping (BVH).

    Raises
    ------
    InputError
        For ``apply`` ids the take does not have.
    """
    if apply == "none":
        return target
    roles = dict(mapping) if isinstance(checked, Motion) and mapping else None
    params = feet_params_of(checked)
    points, report, skipped = check_take_feet(checked, roles, params)
    return fix_feet(checked, points, report, skipped, apply, params, target, roles).take
