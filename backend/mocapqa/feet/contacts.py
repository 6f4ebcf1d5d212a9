"""Foot contacts from height and speed, with hysteresis and minimum durations.

Conventions
-----------
* ``elevations`` ``(F, P)`` are each point's heights above its own stance level (the floor
  plus the point's offset, :class:`mocapqa.feet.floor.Floor`), ``speeds`` ``(F, P)`` its 3D
  speeds; both in take units and take units per second. Thresholds are leg lengths
  (:class:`mocapqa.feet.params.FeetParams`).
* A point enters a contact where it is below ``contact_height`` and slower than
  ``contact_speed``, and stays in it while below ``release_height`` and slower than
  ``release_speed``: the looser second pair keeps a planted foot's noise, and the slow roll of
  a heel strike, from breaking the contact into pieces. Breaks of at most ``max_gap_s`` are
  then closed and contacts shorter than ``min_contact_s`` dropped.
* A foot is in contact where any of its points is (heel or ankle strike, flat foot, push-off
  on the toe), with the same gap and duration rules.
* Confidence is how far inside the keep thresholds a contact sits, averaged over its frames:
  per frame ``min(1 − elevation / release height, 1 − speed / release speed)`` clipped to
  [0, 1], the best point of the foot; times the mean detection confidence of the points when
  the take has one (keypoints).
* Contacts carry 0-based frames with inclusive ends.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, column_runs
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES, per_foot
from mocapqa.feet.runs import (
    close_short_gaps,
    drop_short_runs,
    frames_in,
    hysteresis,
    run_mean,
)

__all__ = [
    "Contact",
    "contact_margins",
    "foot_contact_mask",
    "foot_contacts",
    "point_contact_mask",
]


@dataclass(frozen=True, slots=True)
class Contact:
    """A phase in which a foot (or one of its points) is planted.

    Parameters
    ----------
    foot : {"left", "right"}
    start, end : int
        First and last frame, 0-based, inclusive.
    confidence : float
        0–1 (see the module notes).
    part : str or None
        The point's part (``"heel"``, ``"ankle"``, ``"toe"``) for a point contact, None for
        a foot contact.
    """

    foot: str
    start: int
    end: int
    confidence: float
    part: str | None = None


def point_contact_mask(
    elevations: FloatArray,
    speeds: FloatArray,
    fps: float,
    leg_length: float,
    params: FeetParams | None = None,
) -> BoolArray:
    """Where each point is in contact, with hysteresis and minimum durations.

    Parameters
    ----------
    elevations : ndarray, shape (F, P)
        Heights above each point's stance level, take units (NaN: not in contact).
    speeds : ndarray, shape (F, P)
        Take units per second.
    fps, leg_length, params
        Frames per second, the leg length (take units) and the thresholds (None: the
        defaults).

    Returns
    -------
    ndarray of bool, shape (F, P)
    """
    p = params or FeetParams()
    with np.errstate(invalid="ignore"):
        enter = (elevations < p.contact_height * leg_length) & (
            speeds < p.contact_speed * leg_length
        )
        stay = (elevations < p.release_height * leg_length) & (
            speeds < p.release_speed * leg_length
        )
    mask = hysteresis(enter, stay)
    mask = close_short_gaps(mask, frames_in(p.max_gap_s, fps))
    return drop_short_runs(mask, frames_in(p.min_contact_s, fps))


def foot_contact_mask(
    point_mask: BoolArray, sides: tuple[str, ...], fps: float, params: FeetParams | None = None
) -> BoolArray:
    """Where each foot is in contact: any of its points is, gaps closed, short ones dropped.

    Parameters
    ----------
    point_mask : ndarray of bool, shape (F, P)
    sides : tuple of str
        The side of each point.
    fps : float
    params : FeetParams, optional

    Returns
    -------
    ndarray of bool, shape (F, 2)
        Left foot, then right.
    """
    p = params or FeetParams()
    mask = per_foot(point_mask, sides, np.logical_or)
    mask = close_short_gaps(mask, frames_in(p.max_gap_s, fps))
    return drop_short_runs(mask, frames_in(p.min_contact_s, fps))


def contact_margins(
    elevations: FloatArray,
    speeds: FloatArray,
    leg_length: float,
    params: FeetParams | None = None,
) -> FloatArray:
    """How far inside the keep thresholds each point is, per frame, 0–1 (0 when missing).

    Returns
    -------
    ndarray, shape (F, P)
    """
    p = params or FeetParams()
    with np.errstate(invalid="ignore"):
        height = 1.0 - elevations / (p.release_height * leg_length)
        speed = 1.0 - speeds / (p.release_speed * leg_length)
        margin = np.clip(np.minimum(height, speed), 0.0, 1.0)
    margins: FloatArray = np.nan_to_num(margin, nan=0.0)
    return margins


def foot_contacts(
    point_mask: BoolArray,
    foot_mask: BoolArray,
    margins: FloatArray,
    sides: tuple[str, ...],
    parts: tuple[str, ...],
    detection: FloatArray | None = None,
) -> tuple[list[Contact], list[Contact]]:
    """The foot contacts and the point contacts as lists, with their confidences.

    Parameters
    ----------
    point_mask : ndarray of bool, shape (F, P)
    foot_mask : ndarray of bool, shape (F, 2)
    margins : ndarray, shape (F, P)
        From :func:`contact_margins`.
    sides, parts : tuple of str
        Side and part of each point.
    detection : ndarray, shape (F, P), optional
        Detection confidence of each point (keypoints).

    Returns
    -------
    foot_contacts, point_contacts : list of Contact
        Each sorted by start frame, then foot.
    """
    weights = margins if detection is None else margins * np.nan_to_num(detection, nan=0.0)
    inside = np.where(point_mask, weights, 0.0)
    side_of = [SIDES.index(s) for s in sides]
    best = per_foot(inside, sides, np.maximum)
    feet_runs = column_runs(foot_mask)
    feet = [
        Contact(SIDES[c], int(s), int(e), round(float(v), 3))
        for c, s, e, v in zip(*feet_runs, run_mean(best, feet_runs), strict=True)
    ]
    point_runs = column_runs(point_mask)
    points = [
        Contact(SIDES[side_of[c]], int(s), int(e), round(float(v), 3), parts[c])
        for c, s, e, v in zip(*point_runs, run_mean(weights, point_runs), strict=True)
    ]
    feet.sort(key=lambda c: (c.start, c.foot))
    points.sort(key=lambda c: (c.start, c.foot, c.part or ""))
    return feet, points
