"""The feet check of a take: foot points from a BVH motion or a keypoint sequence, the check,
and its JSON-ready report.

Foot points
-----------
* **BVH**: forward kinematics of the rig; per side the joint of the ``foot`` role (the ankle,
  part ``"ankle"``) and of the ``toe`` role (the ball of the foot) where the rig has one, found
  by :func:`mocapqa.core.rig.find_roles` (or a mapping). The pelvis is the midpoint of the
  ``upper_leg`` joints, the leg length the median of hip → knee → ankle over the take. A
  leading bind pose (:func:`mocapqa.kinematics.bindpose.leading_bind_pose`) is left out and the
  report's frames still count it.
* **Keypoints** (TRC, OpenPose, MediaPipe, CSV, ...): per side the ankle, the heel and the big
  toe (MediaPipe's foot index) by name (``LAnkle``, ``LEFT_HEEL``, ``LBigToe``,
  ``LEFT_FOOT_INDEX``, ...); the heel stands for the rear of the foot where there is one, the
  ankle otherwise. Hips and knees give the pelvis and the leg length. 2D keypoints (OpenPose,
  pixels) are checked in the image plane.
* **Markers** (C3D): per side the heel (or ankle) and toe markers by name, subject prefixes
  left out (:func:`mocapqa.feet.markers.marker_foot_points`).

Units
-----
Sizes are converted to centimetres from the take's length unit (m, cm, mm, in). A BVH file
does not store its unit, so a BVH take's unit is "unknown" unless the reader was told
(``--length-unit``); then, as for pixels and normalised keypoints, ``size_cm`` is null and
``size_rel_height`` (the size over the body height estimated from the leg length) is the
size to read; the report says so in ``sizes``.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles
from mocapqa.core.rig_names import split_side, token_of
from mocapqa.errors import InputError
from mocapqa.feet.check import FeetReport, check_feet
from mocapqa.feet.findings import Finding
from mocapqa.feet.markers import MARKER_PARAMS, marker_foot_points
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import LEG_HEIGHT_RATIO, SIDES, FootPoints, cm_per_unit
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.kinematics.forward import forward_kinematics

__all__ = [
    "KEYPOINT_TOKENS",
    "check_take_feet",
    "feet_params_of",
    "feet_report_json",
    "keypoint_foot_points",
    "motion_foot_points",
]

KEYPOINT_TOKENS: dict[str, tuple[str, ...]] = {
    "hip": ("hip",),
    "knee": ("knee",),
    "ankle": ("ankle",),
    "heel": ("heel",),
    "toe": ("bigtoe", "footindex", "toe", "toes"),
}
"""Name tokens (after the side is split off, see :func:`mocapqa.core.rig_names.split_side`)
of the keypoints the feet check uses, by role; the first token found wins."""


def _leg_length(hips: FloatArray, knees: FloatArray, ankles: FloatArray) -> float:
    """Median over frames and sides of hip → knee → ankle, take units.

    Raises
    ------
    InputError
        If no frame has all three on a side, or the legs have no length.
    """
    legs = np.linalg.norm(hips - knees, axis=-1) + np.linalg.norm(knees - ankles, axis=-1)
    finite = legs[np.isfinite(legs)]
    length = float(np.median(finite)) if finite.size else float("nan")
    if not length > 0:
        raise InputError(
            f"Expected hip, knee and ankle positions that give a leg length > 0, got {length}"
        )
    return length


def motion_foot_points(
    motion: Motion, mapping: Mapping[str, str] | None = None
) -> tuple[FootPoints, int]:
    """The foot points of a BVH take, and the leading bind-pose frames left out.

    Parameters
    ----------
    motion : Motion
    mapping : mapping, optional
        Role key → joint name, overriding the roles found by name.

    Returns
    -------
    points : FootPoints
        From the first frame after the bind pose.
    skipped : int
        Leading bind-pose frames left out (0 or 1).

    Raises
    ------
    InputError
        If the rig has no foot, upper-leg or lower-leg joint on a side.
    """
    skeleton = motion.skeleton
    rig = find_roles(skeleton, mapping)
    missing = [
        f"{side}_{role}"
        for side in SIDES
        for role in ("upper_leg", "lower_leg", "foot")
        if rig.joint(side, role) is None
    ]
    if missing:
        raise InputError(
            f"Expected a rig with upper leg, lower leg and foot joints on both sides, got none "
            f"for {', '.join(missing)} (name them with --mapping FILE, see docs/rigs.md)"
        )
    skipped = leading_bind_pose(motion.quats) if motion.n_frames > 3 else 0
    _, world = forward_kinematics(motion)
    world = world[skipped:]
    joints, sides, parts = [], [], []
    for side in SIDES:
        for role, part in (("foot", "ankle"), ("toe", "toe")):
            joint = rig.joint(side, role)
            if joint is not None:
                joints.append(joint)
                sides.append(side)
                parts.append(part)
    hips = world[:, [rig.roles[f"{s}_upper_leg"] for s in SIDES]]
    knees = world[:, [rig.roles[f"{s}_lower_leg"] for s in SIDES]]
    ankles = world[:, [rig.roles[f"{s}_foot"] for s in SIDES]]
    points = FootPoints(
        positions=world[:, joints],
        sides=tuple(sides),
        parts=tuple(parts),
        names=tuple(skeleton.names[j] for j in joints),
        fps=motion.fps,
        leg_length=_leg_length(hips, knees, ankles),
        length_unit=skeleton.length_unit,
        pelvis=hips.mean(axis=1),
    )
    return points, skipped


def _keypoint_roles(names: tuple[str, ...]) -> dict[tuple[str, str], int]:
    """(side, role) → keypoint index, for the roles of :data:`KEYPOINT_TOKENS`."""
    by_token: dict[tuple[str, str], int] = {}
    for index, name in enumerate(names):
        named_side, rest = split_side(name)
        if named_side is not None:
            by_token.setdefault((named_side, token_of(rest)), index)
    found: dict[tuple[str, str], int] = {}
    for side in SIDES:
        for role, tokens in KEYPOINT_TOKENS.items():
            for token in tokens:
                if (side, token) in by_token:
                    found[(side, role)] = by_token[(side, token)]
                    break
    return found


def keypoint_foot_points(sequence: KeypointSequence) -> FootPoints:
    """The foot points of a keypoint take.

    Raises
    ------
    InputError
        If a side has no ankle, hip or knee keypoint.
    """
    roles = _keypoint_roles(sequence.names)
    missing = [
        f"{side} {role}"
        for side in SIDES
        for role in ("hip", "knee", "ankle")
        if (side, role) not in roles
    ]
    if missing:
        raise InputError(
            f"Expected hip, knee and ankle keypoints on both sides, got none for "
            f"{', '.join(missing)} (keypoints: {', '.join(sequence.names[:8])}"
            f"{', ...' if len(sequence.names) > 8 else ''})"
        )
    indices, sides, parts = [], [], []
    for side in SIDES:
        rear = ("heel", "heel") if (side, "heel") in roles else ("ankle", "ankle")
        for role, part in (rear, ("toe", "toe")):
            if (side, role) in roles:
                indices.append(roles[(side, role)])
                sides.append(side)
                parts.append(part)
    positions = sequence.positions

    def at(role: str) -> FloatArray:
        picked: FloatArray = positions[:, [roles[(s, role)] for s in SIDES]]
        return picked

    hips = at("hip")
    with warnings.catch_warnings():
        # A frame where neither hip was detected has no pelvis: NaN, not a warning.
        warnings.simplefilter("ignore", RuntimeWarning)
        pelvis = np.nanmean(hips, axis=1)
    return FootPoints(
        positions=positions[:, indices],
        sides=tuple(sides),
        parts=tuple(parts),
        names=tuple(sequence.names[i] for i in indices),
        fps=sequence.fps,
        leg_length=_leg_length(hips, at("knee"), at("ankle")),
        length_unit=sequence.length_unit,
        pelvis=pelvis if np.isfinite(pelvis).any() else None,
        confidence=sequence.confidence[:, indices],
    )


def check_take_feet(
    take: Motion | KeypointSequence,
    mapping: Mapping[str, str] | None = None,
    params: FeetParams | None = None,
) -> tuple[FootPoints, FeetReport, int]:
    """Foot points and the feet check of a take.

    Parameters
    ----------
    take : Motion or KeypointSequence
        A BVH motion, or keypoints (a C3D take's markers when ``source_format`` is "c3d").
    mapping : mapping, optional
        Role key → joint name (BVH only).
    params : FeetParams, optional
        Thresholds; None gives the defaults, or
        :data:`mocapqa.feet.markers.MARKER_PARAMS` for a C3D take.

    Returns
    -------
    points : FootPoints
    report : FeetReport
        Frames counted from the first checked frame.
    skipped : int
        Leading frames left out (a BVH bind pose); add it to the report's frames.

    Raises
    ------
    InputError
        If the take has no usable feet, or fewer than 2 frames.
    """
    if take.n_frames < 2:
        raise InputError(f"Expected a take of at least 2 frames, got {take.n_frames}")
    if isinstance(take, Motion):
        points, skipped = motion_foot_points(take, mapping)
    else:
        if mapping:
            raise InputError("Expected --mapping only for a BVH take, got a keypoint take")
        markers = take.source_format == "c3d"
        points = marker_foot_points(take) if markers else keypoint_foot_points(take)
        skipped = 0
    return points, check_feet(points, feet_params_of(take) if params is None else params), skipped


def feet_params_of(take: Motion | KeypointSequence) -> FeetParams:
    """The feet check's thresholds for a take, the one choice the run's feet step, ``mocapqa
    feet check/fix`` and the decided download share: :data:`mocapqa.feet.markers.MARKER_PARAMS`
    for a C3D take's markers, the defaults for a BVH take and for keypoints (a TRC take's
    points are read as keypoints, by their names)."""
    if isinstance(take, KeypointSequence) and take.source_format == "c3d":
        return MARKER_PARAMS
    return FeetParams()


def _round(value: float | None, digits: int = 4) -> float | None:
    if value is None or not np.isfinite(value):
        return None
    return round(float(value), digits)


def _finding_json(
    finding: Finding, skipped: int, height: float, to_cm: float | None
) -> dict[str, Any]:
    """One finding of :func:`feet_report_json`."""
    item: dict[str, Any] = {
        "kind": finding.kind,
        "foot": finding.foot,
        "start": finding.start + skipped,
        "end": finding.end + skipped,
        "peak": finding.peak + skipped,
        "size": _round(finding.size, 5),
        "size_cm": _cm(finding.size, to_cm),
        "size_rel_height": _round(finding.size / height, 5),
    }
    if finding.speed is not None:
        item["speed_cm_s"] = _cm(finding.speed, to_cm)
        item["speed_rel_height_s"] = _round(finding.speed / height, 5)
    return item


def _cm(value: float | None, to_cm: float | None) -> float | None:
    """A size in take units in centimetres, rounded; None where the unit does not convert."""
    return None if value is None or to_cm is None else _round(value * to_cm, 3)


def _sizes_json(points: FootPoints, to_cm: float | None) -> dict[str, Any]:
    """The units, leg length and body height of :func:`feet_report_json`."""
    return {
        "length_unit": points.length_unit,
        "cm_per_unit": to_cm,
        "sizes": "cm"
        if to_cm is not None
        else (
            f"unit {points.length_unit!r} does not convert to cm: size_cm is null; read "
            "size_rel_height (size over the body height estimated from the leg length)"
        ),
        "leg_length": _round(points.leg_length, 5),
        "leg_length_cm": _cm(points.leg_length, to_cm),
        "body_height_estimate": _round(points.body_height, 5),
        "body_height_note": f"leg length / {LEG_HEIGHT_RATIO} (hip-knee-ankle over stature)",
    }


def _floor_json(report: FeetReport, skipped: int, to_cm: float | None) -> dict[str, Any]:
    """The up axis, floor level and ``floor_check`` of :func:`feet_report_json`."""
    up, floor = report.up, report.floor
    return {
        "up_axis": up.label,
        "up_axis_detail": {
            "method": up.method,
            "feet_spreads_leg": [_round(s, 5) for s in up.feet_spreads],
            "body_axis": None if up.body_axis is None else "XYZ"[up.body_axis],
        },
        "floor": _round(up.sign * floor.level, 5),
        "floor_check": {
            "tilt_deg": _round(floor.tilt_deg, 3),
            "rise": _round(floor.rise, 5),
            "rise_cm": _cm(floor.rise, to_cm),
            "drift": _round(floor.drift, 5),
            "drift_cm": _cm(floor.drift, to_cm),
            "tilted": floor.tilted,
            "moving": floor.moving,
            "plane_gradient": None
            if floor.gradient is None
            else [_round(g, 6) for g in floor.gradient],
            "plane_origin": [_round(o, 5) for o in floor.origin],
            "heights_from": "the tilted plane through `floor` at `plane_origin`"
            if floor.tilted
            else "the level floor",
            "segments": [
                {"start": s + skipped, "end": e + skipped, "floor": _round(up.sign * level, 5)}
                for s, e, level in floor.segments
            ],
            "stance_samples": floor.n_samples,
        },
    }


def _contacts_json(report: FeetReport, skipped: int) -> dict[str, Any]:
    """The ``contacts`` and ``point_contacts`` of :func:`feet_report_json`."""
    return {
        "contacts": [
            {
                "foot": c.foot,
                "start": c.start + skipped,
                "end": c.end + skipped,
                "confidence": c.confidence,
            }
            for c in report.contacts
        ],
        "point_contacts": [
            {
                "foot": c.foot,
                "part": c.part,
                "start": c.start + skipped,
                "end": c.end + skipped,
                "confidence": c.confidence,
            }
            for c in report.point_contacts
        ],
    }


def _summary_json(report: FeetReport, minutes: float) -> dict[str, Any]:
    """The ``summary`` of :func:`feet_report_json`: counts by foot and kind, skate rate."""
    return {
        "contacts": {s: sum(c.foot == s for c in report.contacts) for s in SIDES},
        "findings": {
            k: sum(f.kind == k for f in report.findings)
            for k in ("skate", "penetration", "floating", "jitter")
        },
        "skate_per_minute": _round(sum(f.kind == "skate" for f in report.findings) / minutes, 3)
        if minutes > 0
        else None,
    }


def feet_report_json(points: FootPoints, report: FeetReport, skipped: int = 0) -> dict[str, Any]:
    """The feet check as a JSON-ready dict (the ``mocapqa feet check --json`` object).

    Parameters
    ----------
    points : FootPoints
    report : FeetReport
    skipped : int
        Leading frames left out of the check; added to every frame number.

    Returns
    -------
    dict
        ``up_axis``, ``floor`` (the floor's coordinate on the up axis, take units),
        ``floor_check`` (tilt, rise, drift, segments), ``contacts`` and ``point_contacts``
        (``foot``, ``start``, ``end``, ``confidence``), ``findings`` (``kind``, ``foot``,
        ``start``, ``end``, ``peak``, ``size``, ``size_cm``, ``size_rel_height``, skate
        ``speed_cm_s``), the units and scale used, and a summary. Frames are 0-based and
        ends inclusive, counted in the take as read.
    """
    to_cm = cm_per_unit(points.length_unit)
    frames = report.contact_mask.shape[0]
    return {
        "frames": frames + skipped,
        "checked_frames": [skipped, frames + skipped - 1],
        "fps": points.fps,
        **_sizes_json(points, to_cm),
        **_floor_json(report, skipped, to_cm),
        "points": [
            {
                "name": name,
                "foot": side,
                "part": part,
                "stance_above_floor": _round(float(offset), 5),
            }
            for name, side, part, offset in zip(
                points.names, points.sides, points.parts, report.floor.point_offsets, strict=True
            )
        ],
        "bind_pose_frames": skipped,
        **_contacts_json(report, skipped),
        "findings": [_finding_json(f, skipped, points.body_height, to_cm) for f in report.findings],
        "summary": _summary_json(report, frames / points.fps / 60.0),
    }
