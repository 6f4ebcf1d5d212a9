"""Where the skate check looks: the contacts, and the low phases that move too fast to be one.

Conventions
-----------
* A foot slides while its points stay at floor level: a slide faster than ``release_speed``
  breaks the contact it happens in (the foot is no longer still), and the pieces left may be
  shorter than ``min_contact_s``, so the contact's own travel never sees it. The skate check
  therefore reads runs of frames where the foot is in contact **or** every one of its points
  is below ``slide_height`` above its stance level (a lifted foot has at least one point up:
  the toe at a heel strike, the heel at push-off, both in swing), with breaks up to
  ``max_gap_s`` closed and runs under ``min_contact_s`` dropped.
* A point carries the foot (:func:`mocapqa.feet.findings.find_skate`) where it is in contact,
  or below ``slide_height`` on the frames these runs add.
* Masks are ``(F, P)`` per point and ``(F, 2)`` per foot (left, right), as in
  :mod:`mocapqa.feet.contacts`.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES, per_foot
from mocapqa.feet.runs import close_short_gaps, drop_short_runs, frames_in

__all__ = ["skate_masks"]


def skate_masks(
    elevations: FloatArray,
    speeds: FloatArray,
    point_mask: BoolArray,
    foot_mask: BoolArray,
    sides: tuple[str, ...],
    fps: float,
    leg_length: float,
    params: FeetParams | None = None,
) -> tuple[BoolArray, BoolArray]:
    """The point and foot masks the skate check reads (see the module notes).

    Parameters
    ----------
    elevations : ndarray, shape (F, P)
        Heights above each point's stance level, take units (NaN: missing, never low).
    speeds : ndarray, shape (F, P)
        Speeds of the smoothed tracks, take units per second.
    point_mask : ndarray of bool, shape (F, P)
        Point contacts.
    foot_mask : ndarray of bool, shape (F, 2)
        Foot contacts.
    sides : tuple of str
    fps, leg_length, params
        Frames per second, the leg length (take units) and the thresholds (None: the
        defaults); ``slide_height`` 0 gives the contacts as they are.

    Returns
    -------
    point_mask : ndarray of bool, shape (F, P)
    foot_mask : ndarray of bool, shape (F, 2)
    """
    p = params or FeetParams()
    if p.slide_height <= 0:
        return point_mask, foot_mask
    with np.errstate(invalid="ignore"):
        low = (elevations < p.slide_height * leg_length) & (speeds < p.slide_speed * leg_length)
    feet = close_short_gaps(foot_mask | per_foot(low, sides, np.logical_and),
                            frames_in(p.max_gap_s, fps))  # fmt: skip
    feet = drop_short_runs(feet, frames_in(p.min_contact_s, fps))
    side_of = np.array([SIDES.index(s) for s in sides], dtype=np.intp)
    points: BoolArray = point_mask | (low & feet[:, side_of])
    return points, feet
