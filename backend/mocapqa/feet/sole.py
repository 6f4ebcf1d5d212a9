"""The sole under a foot point: what a planted foot's pivot is read from.

Conventions
-----------
* A foot is its rear point (heel or ankle) and its toe, each with a position and a velocity
  (of the smoothed tracks) in take units and take units per second; the foot between them is
  rigid. Two points give its angular velocity up to a spin about the line between them; the
  smallest is taken, ``ω = r × d / |r|²`` with ``r = p_toe − p_rear`` and
  ``d = v_toe − v_rear``. It is exact for a pitch (rolling over the heel or the toe: the axis
  is square to the foot) and for a yaw of a level foot; with the ankle above the toe a yaw
  reads partly as a pitch. Choosing the spin that leaves no roll about the foot's horizontal
  direction (no inversion or eversion), which reads a yaw whole, flagged more clean turning
  steps of the fit takes (the largest clean travel 0.022 leg against 0.014).
* The sole under a point lies ``h`` below it (the point's height above the sole), so the
  sole's velocity is the point's plus ``ω × (−h · up)``; only ``ω × up`` is needed,
  ``((r × d) × up) / |r|² = (d (r · up) − r (d · up)) / |r|²``.
* A foot rolling over its heel or its toe (pitch about a point on the floor) carries its
  joints forward or back above the floor, but not its sole: sole points at floor level move
  vertically only. A sliding foot moves its sole as much as its joints. Along the rear → toe
  line the sole's velocities still vary linearly (``h`` varies linearly along it), so a foot
  turning about a point under that line has a sole point that stays.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.feet.ground import UpAxis

__all__ = ["sole_sweep"]


def sole_sweep(span: FloatArray, change: FloatArray, up: UpAxis) -> FloatArray:
    """``ω × up`` of a rigid foot, per row: the sole under a point ``h`` above it moves at
    the point's velocity minus ``h`` times this.

    Parameters
    ----------
    span : ndarray, shape (N, 3)
        Toe position minus rear position, take units.
    change : ndarray, shape (N, 3)
        Toe velocity minus rear velocity, take units per second.
    up : UpAxis
        The up direction.

    Returns
    -------
    ndarray, shape (N, 3)
        Radians per second; zero in rows where either input is missing or the two points
        coincide.
    """
    length2 = np.einsum("nk,nk->n", span, span)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(length2 > 0, up.sign / length2, 0.0)
    span_up = (span[:, up.axis] * scale)[:, None]
    change_up = (change[:, up.axis] * scale)[:, None]
    sweep = change * span_up - span * change_up
    swept: FloatArray = np.nan_to_num(sweep, nan=0.0, posinf=0.0, neginf=0.0)
    return swept
