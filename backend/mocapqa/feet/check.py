"""The feet check of one take: up axis, floor, contacts and findings, from its foot points.

``check_feet(points, params)`` runs the steps in order on one smoothed copy of the tracks:

1. speeds of every point (moving average over ``speed_window_s``, central differences);
2. the up axis (:func:`mocapqa.feet.ground.detect_up_axis`), unless the caller names it;
3. the floor and each point's stance level (:func:`mocapqa.feet.floor.fit_floor`); a tilted
   floor is reported, and heights are then measured from its plane (fitted again on the
   levelled heights for the stance levels and the drift);
4. point and foot contacts (:mod:`mocapqa.feet.contacts`), the foot contacts' edges moved to
   the heel's impact and the toe's push-off when the event window is on (marker takes,
   :mod:`mocapqa.feet.events`);
5. skate (over the contacts and the low phases too fast for one, :mod:`mocapqa.feet.slides`,
   reading the sole under the points, :mod:`mocapqa.feet.sole`), penetration, floating and
   jitter (:mod:`mocapqa.feet.findings`).

Everything stays in take units; the caller converts sizes (``mocapqa.pipeline.feet``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.feet.contacts import (
    Contact,
    contact_margins,
    foot_contact_mask,
    foot_contacts,
    point_contact_mask,
)
from mocapqa.feet.events import refine_contact_edges
from mocapqa.feet.findings import (
    FINDING_KINDS,
    Finding,
    find_floating,
    find_jitter,
    find_penetration,
    find_skate,
)
from mocapqa.feet.floor import Floor, fit_floor
from mocapqa.feet.ground import UpAxis, detect_up_axis
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import FootPoints
from mocapqa.feet.slides import skate_masks
from mocapqa.feet.tracks import (
    horizontal_axes,
    moving_average,
    norms,
    smoothing_window,
    velocities,
)

__all__ = ["FeetReport", "check_feet"]


@dataclass(frozen=True, slots=True)
class FeetReport:
    """What the feet check found in a take.

    Parameters
    ----------
    up : UpAxis
    floor : Floor
    contacts : tuple of Contact
        Foot contacts, by start frame.
    point_contacts : tuple of Contact
        Contacts of each point (heel or ankle, toe), by start frame.
    findings : tuple of Finding
        By kind (:data:`mocapqa.feet.findings.FINDING_KINDS` order), then start frame.
    contact_mask : ndarray of bool, shape (F, 2)
        Per frame, whether the left and the right foot are in contact.
    elevations : ndarray, shape (F, P)
        Height of each point above its stance level (the floor plus its offset), smoothed,
        take units.
    """

    up: UpAxis
    floor: Floor
    contacts: tuple[Contact, ...]
    point_contacts: tuple[Contact, ...]
    findings: tuple[Finding, ...]
    contact_mask: BoolArray
    elevations: FloatArray


def _skate(
    points: FootPoints,
    p: FeetParams,
    smooth: FloatArray,
    velocity: FloatArray,
    speeds: FloatArray,
    elevations: FloatArray,
    point_mask: BoolArray,
    foot_mask: BoolArray,
    floor: Floor,
    up: UpAxis,
) -> list[Finding]:
    """The skate findings: over the contacts and the low phases too fast for one (slides that
    broke their contact, :mod:`mocapqa.feet.slides`), reading the sole under each point, its
    height above the floor plus ``sole_depth`` (:mod:`mocapqa.feet.sole`)."""
    leg = points.leg_length
    skate_points, skate_feet = skate_masks(
        elevations, speeds, point_mask, foot_mask, points.sides, points.fps, leg, p
    )
    depths = elevations + floor.point_offsets + p.sole_depth * leg
    return find_skate(
        velocity, speeds, elevations, skate_points, skate_feet, points.sides,
        horizontal_axes(up.axis), points.fps, leg, p,
        sole=(smooth, depths, up) if p.sole_pivot else None,
    )  # fmt: skip


def check_feet(
    points: FootPoints, params: FeetParams | None = None, up: UpAxis | None = None
) -> FeetReport:
    """Check the feet of a take.

    Parameters
    ----------
    points : FootPoints
        World positions of the foot points, take units.
    params : FeetParams, optional
        Thresholds (defaults when None).
    up : UpAxis, optional
        The up axis, when known; detected when None.

    Returns
    -------
    FeetReport

    Raises
    ------
    InputError
        If the points have no usable positions.
    """
    p = params or FeetParams()
    leg = points.leg_length
    positions = points.positions
    smooth = moving_average(positions, smoothing_window(points.fps, p.speed_window_s))
    velocity = velocities(smooth, points.fps)
    speeds = norms(velocity)
    with np.errstate(invalid="ignore"):
        static = speeds < p.contact_speed * leg
    if up is None:
        up = detect_up_axis(positions, points.parts, static, leg, points.pelvis)
    heights = up.heights(smooth)
    flat_axes = horizontal_axes(up.axis)
    flat = smooth[..., list(flat_axes)]
    floor = fit_floor(heights, flat, static, points.sides, points.fps, leg, p)
    if floor.tilted:
        # Reported, and then measured from: heights above the tilted plane, so that one end
        # of the room is not all penetration and the other all floating. The stance levels
        # and the drift are measured again on the levelled heights.
        heights = heights - floor.plane(flat)
        levelled = fit_floor(heights, flat, static, points.sides, points.fps, leg, p)
        floor = dataclasses.replace(
            levelled, tilt_deg=floor.tilt_deg, rise=floor.rise, tilted=True,
            gradient=floor.gradient, origin=floor.origin,
        )  # fmt: skip
    elevations = heights - (floor.level + floor.point_offsets)
    point_mask = point_contact_mask(elevations, speeds, points.fps, leg, p)
    foot_mask = foot_contact_mask(point_mask, points.sides, points.fps, p)
    foot_mask = refine_contact_edges(foot_mask, positions, points.sides, up, points.fps, p)
    margins = contact_margins(elevations, speeds, leg, p)
    feet, per_point = foot_contacts(
        point_mask, foot_mask, margins, points.sides, points.parts, points.confidence
    )
    skates = _skate(
        points, p, smooth, velocity, speeds, elevations, point_mask, foot_mask, floor, up
    )
    findings = [
        *skates,
        *find_penetration(elevations, floor.point_spreads, points.sides, points.fps, leg, p),
        *find_floating(elevations, speeds, foot_mask, points.sides, points.fps, leg, p),
        *find_jitter(positions, speeds, point_mask, foot_mask, points.sides, leg, p),
    ]
    findings.sort(key=lambda f: (FINDING_KINDS.index(f.kind), f.start, f.foot))
    return FeetReport(
        up, floor, tuple(feet), tuple(per_point), tuple(findings), foot_mask, elevations
    )
