"""Contact edges moved to the foot's kinematic events: the heel's impact and the toe's push-off.

Conventions
-----------
* The contacts of :mod:`mocapqa.feet.contacts` start when a point is low and slow, and end
  when every point is high or fast; against force plates a heel marker is still slowing when
  the plate is first loaded, and the toe has not yet left when it speeds up. The usual
  kinematic gait events mark the instants themselves (Hreljac & Marshall 2000): **foot
  strike** at the largest upward acceleration of the heel (the impact that stops its fall),
  **toe-off** at the largest horizontal acceleration of the toe.
* Each foot contact's first frame moves to the frame of the largest upward acceleration of
  the foot's rear point (heel or ankle) within ``event_before_s`` before it and
  ``event_after_s`` after it, and its last frame to that of the largest horizontal
  acceleration of the toe (the rear point when the foot has no toe) within the same window
  around it. A contact keeps at least its first frame, never reaches into the neighbouring
  contacts of its foot, and keeps an edge where the window has no positive acceleration
  larger than at the edge itself, or where the edge is the take's first or last frame.
* Accelerations are second differences of the raw tracks, take units per second squared:
  a moving average of even 3 frames at 50 fps spreads the impact over the frames before it.
* ``event_before_s`` and ``event_after_s`` 0 leave the contacts as they are.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, column_runs
from mocapqa.feet.findings import foot_pair
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.params import FeetParams
from mocapqa.feet.runs import paint_runs
from mocapqa.feet.tracks import horizontal_axes, norms

__all__ = ["event_signals", "refine_contact_edges"]


def event_signals(
    positions: FloatArray, sides: tuple[str, ...], up: UpAxis, fps: float
) -> tuple[FloatArray, FloatArray]:
    """Per foot, the upward acceleration of its rear point and the horizontal acceleration
    (magnitude) of its toe.

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
        Raw point positions, take units; NaN where missing.
    sides : tuple of str
    up : UpAxis
    fps : float

    Returns
    -------
    strike, push : ndarray, shape (F, 2)
        Take units per second squared; NaN at the first and last frame and where a sample
        is missing.
    """
    rear, toe = foot_pair(sides)
    strike = np.full((positions.shape[0], 2), np.nan)
    push = np.full((positions.shape[0], 2), np.nan)
    if positions.shape[0] >= 3:
        second = (positions[2:] - 2.0 * positions[1:-1] + positions[:-2]) * fps * fps
        strike[1:-1] = up.sign * second[:, rear, up.axis]
        push[1:-1] = norms(second[:, toe][..., list(horizontal_axes(up.axis))])
    return strike, push


def _peak_frames(signal: FloatArray, column: IntArray, centre: IntArray, before: int,
                 after: int, lowest: IntArray, highest: IntArray) -> IntArray:  # fmt: skip
    """Per edge, the frame of the largest finite ``signal[:, column]`` within
    ``centre − before .. centre + after`` clipped to ``lowest .. highest``; ``centre`` where
    there is none, where it is not positive or no larger than at ``centre`` (a flat signal
    moves nothing), and where ``centre`` is the take's first or last frame (a contact cut by
    the take's ends keeps them)."""
    offsets = np.arange(-before, after + 1)
    frames = centre[:, None] + offsets[None, :]  # (E, W)
    inside = (frames >= lowest[:, None]) & (frames <= highest[:, None])
    values = signal[np.clip(frames, 0, signal.shape[0] - 1), column[:, None]]
    values = np.where(inside & np.isfinite(values), values, -np.inf)
    best = np.argmax(values, axis=1)
    here = signal[centre, column]
    top = values[np.arange(best.size), best]
    cut = (centre == 0) | (centre == signal.shape[0] - 1)
    found = np.isfinite(top) & (top > 0) & ~(top <= here) & ~cut
    peaks: IntArray = np.where(found, frames[np.arange(best.size), best], centre)
    return peaks


def refine_contact_edges(
    foot_mask: BoolArray,
    positions: FloatArray,
    sides: tuple[str, ...],
    up: UpAxis,
    fps: float,
    params: FeetParams | None = None,
) -> BoolArray:
    """The foot contacts with their edges moved to the kinematic events (module notes).

    Parameters
    ----------
    foot_mask : ndarray of bool, shape (F, 2)
        Foot contacts (left, right).
    positions : ndarray, shape (F, P, 3)
        Raw point positions, take units.
    sides : tuple of str
    up : UpAxis
    fps : float
    params : FeetParams, optional
        ``event_before_s`` and ``event_after_s`` give the window.

    Returns
    -------
    ndarray of bool, shape (F, 2)
    """
    p = params or FeetParams()
    before, after = round(p.event_before_s * fps), round(p.event_after_s * fps)
    columns, starts, ends = column_runs(foot_mask)
    if (before == 0 and after == 0) or columns.size == 0:
        return foot_mask
    strike, push = event_signals(positions, sides, up, fps)
    # Neighbouring contacts of the same foot bound each edge (runs come by column, then
    # start), as do the take's ends.
    same_before = np.r_[False, columns[1:] == columns[:-1]]
    same_after = np.r_[columns[:-1] == columns[1:], False]
    floor = np.where(same_before, np.r_[0, ends[:-1]] + 1, 0)
    new_starts = _peak_frames(strike, columns, starts, before, after, floor, ends)
    # A frame apart from the next contact's new start, so the two do not merge.
    ceiling = np.where(same_after, np.r_[new_starts[1:], 0] - 2, foot_mask.shape[0] - 1)
    ceiling = np.maximum(ceiling, new_starts)
    new_ends = _peak_frames(push, columns, ends, before, after, new_starts, ceiling)
    return paint_runs((columns, new_starts, new_ends), foot_mask.shape)
