"""Foot locks: how far a planted foot's pivot slid over a contact, and the horizontal offsets
that hold it, blended in and out.

Conventions
-----------
* Frames are the take's (0-based, inclusive ends); contacts from the feet check, whose frames
  start after a leading bind pose, are shifted by the caller. Positions are take units.
* **The pivot.** A planted foot that rolls (heel strike, push-off over the toe) has a point
  that stays; a foot that slides moves every point. Per frame and foot, the pivot's step is
  the horizontal step of the point of the rear → toe line that moved least since the previous
  frame (a rigid foot's velocities vary linearly along the line), as in the skate check.
  With the points' heights above the sole (``depths``) the steps are those of the sole under
  each point (:mod:`mocapqa.feet.sole`), what the skate check reads: a foot rolling over its
  heel or toe carries its joints forward above a sole point that stays, and holding the
  joints through the roll would move the sole under them.
* **Planted.** Over a contact, the pivot's steps count where the pivot (averaged over
  :data:`SPEED_WINDOW_S`) is slower than ``plant_speed`` or than 1.5 times its median speed
  over the contact, the frames the skate check counts; on the other frames (a clean step's
  landing and push-off) only the steady slide (the median counted step) counts. The running
  sum is the contact's **planted track**, its largest distance from the first frame the
  **slide**.
* **The lock.** During a locked contact the foot moves horizontally by minus its planted
  track, relative to an anchor: the contact's middle frame (the default) or the mean of its
  first ``blend_s`` (``"start"``); with the middle, what the lock removes is split between the
  blend in and the blend out. Heights are left as they are (a 3D lock of the ankle pressed the
  heel down through every push-off). Before the contact the offset is the contact's first
  one, after it the last, weighted by a smoothstep over ``blend_s`` on either side, so frames
  outside contacts and blends are not touched and the foot eases into and out of the lock.
  Overlapping blends of one foot are averaged by weight.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.feet.findings import run_median
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.points import SIDES
from mocapqa.feet.sole import sole_sweep
from mocapqa.feet.tracks import horizontal_axes, smoothing_window

__all__ = [
    "BLEND_S",
    "SPEED_WINDOW_S",
    "Anchor",
    "Lock",
    "lock_offsets",
    "pivot_steps",
    "planted_tracks",
    "planted_travel",
    "sole_heights",
]

Anchor = Literal["middle", "start"]
"""Where a lock takes the held position from: the contact's middle frame or its start."""
BLEND_S = 0.1
"""Seconds over which a lock eases in before a contact and out after it."""
SPEED_WINDOW_S = 0.1
"""Seconds of the moving average of the pivot's steps before its speed decides which frames are
planted (the feet check's ``speed_window_s``)."""


@dataclass(frozen=True, slots=True)
class Lock:
    """One contact to lock.

    Parameters
    ----------
    foot : {"left", "right"}
    start, end : int
        First and last frame of the contact, motion frames, inclusive.
    """

    foot: str
    start: int
    end: int


def sole_heights(
    elevations: FloatArray,
    offsets: FloatArray,
    sides: Sequence[str],
    depth: float,
    skipped: int,
    n_frames: int,
) -> FloatArray:
    """Each foot point's height above the sole, as the skate check reads it, in the order of
    :func:`pivot_steps`' points (the left foot's points, then the right's).

    Parameters
    ----------
    elevations : ndarray, shape (C, P)
        The feet check's heights of the points above their stance levels over its checked
        frames, take units.
    offsets : ndarray, shape (P,)
        Each point's stance level above the floor, take units.
    sides : sequence of str
        Each point's foot.
    depth : float
        The sole below the floor (``sole_depth`` times the leg length), take units.
    skipped : int
        Leading frames the check left out (a bind pose): their heights are 0.
    n_frames : int
        Frames of the take.

    Returns
    -------
    ndarray, shape (F, P)
        Take units, at least 0, 0 where a point is missing.
    """
    order = [i for side in SIDES for i, s in enumerate(sides) if s == side]
    values = elevations[:, order] + np.asarray(offsets)[order] + depth
    heights = np.zeros((n_frames, len(order)))
    rows = min(values.shape[0], n_frames - skipped)
    heights[skipped : skipped + rows] = np.clip(np.nan_to_num(values[:rows], nan=0.0), 0.0, None)
    return heights


def pivot_steps(
    positions: FloatArray,
    rig_points: Sequence[Sequence[int]],
    up: UpAxis,
    depths: FloatArray | None = None,
) -> FloatArray:
    """Each foot's pivot step per frame (see the module notes).

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
        Foot points, take units.
    rig_points : sequence of sequence of int
        Per side (left, right), the indices in ``positions`` of the rear point (ankle) and,
        when the foot has one, the toe.
    up : UpAxis
    depths : ndarray, shape (F, P), optional
        Each point's height above the sole (:func:`sole_heights`), take units: the steps are
        then those of the sole under the points. None reads the points themselves.

    Returns
    -------
    ndarray, shape (F, 2, 2)
        Per frame and foot (left, right), the horizontal step since the previous frame of the
        point of the rear → toe line that moved least (zero at frame 0), take units.
    """
    moves = np.diff(positions, axis=0)  # (F-1, P, 3)
    if depths is not None:
        rear_index = [points[0] for points in rig_points]
        toe_index = [points[-1] for points in rig_points]
        middle = 0.5 * (positions[1:] + positions[:-1])
        span = (middle[:, toe_index] - middle[:, rear_index]).reshape(-1, 3)
        change = (moves[:, toe_index] - moves[:, rear_index]).reshape(-1, 3)
        sweep = sole_sweep(span, change, up).reshape(-1, len(rig_points), 3)
        side_of = np.zeros(positions.shape[1], dtype=np.intp)
        for foot, points in enumerate(rig_points):
            side_of[list(points)] = foot
        drop = 0.5 * (depths[1:] + depths[:-1])
        moves = moves - drop[..., None] * sweep[:, side_of]
    steps = moves[..., list(horizontal_axes(up.axis))]  # (F-1, P, 2)
    rear = steps[:, [points[0] for points in rig_points]]  # (F-1, 2, 2)
    span = steps[:, [points[-1] for points in rig_points]] - rear
    with np.errstate(invalid="ignore", divide="ignore"):
        share = -np.sum(rear * span, axis=-1) / np.sum(span * span, axis=-1)
    share = np.clip(np.nan_to_num(share), 0.0, 1.0)
    out = np.zeros((positions.shape[0], 2, 2))
    out[1:] = rear + share[..., None] * span
    return out


def planted_tracks(
    steps: FloatArray, locks: Sequence[Lock], fps: float, plant_speed: float
) -> tuple[FloatArray, IntArray]:
    """Each contact's planted pivot displacement: the running sum from its first frame of the
    pivot's steps on the frames where the pivot (its steps averaged over
    :data:`SPEED_WINDOW_S`) is slower than ``plant_speed`` or than 1.5 times its median speed
    over the contact (the frames the skate check counts), and of the median of those steps
    (the steady slide) on the others: the landing and push-off of a clean step are left as
    they are, while a steady slide is taken out in full.

    Parameters
    ----------
    steps : ndarray, shape (F, 2, 2)
        :func:`pivot_steps`.
    locks : sequence of Lock
        The contacts.
    fps : float
    plant_speed : float
        Take units per second.

    Returns
    -------
    tracks : ndarray, shape (N, 2)
        The contacts' frames one after the other (``end − start + 1`` rows each), zero at
        each contact's first frame, take units.
    firsts : ndarray of int, shape (L,)
        Each contact's first row in ``tracks``.
    """
    starts = np.array([k.start for k in locks], dtype=np.intp)
    ends = np.array([k.end for k in locks], dtype=np.intp)
    feet = np.array([SIDES.index(k.foot) for k in locks], dtype=np.intp)
    moves = ends - starts  # steps per contact (after its first frame)
    run = np.repeat(np.arange(len(locks)), moves)
    firsts_moves = np.cumsum(moves) - moves
    local = np.arange(int(moves.sum())) - firsts_moves[run]
    own = steps[starts[run] + 1 + local, feet[run]]  # (M, 2)
    # Moving average within each contact, the window shrinking at its ends.
    half = smoothing_window(fps, SPEED_WINDOW_S) // 2
    sums = np.concatenate([np.zeros((1, 2)), np.cumsum(own, axis=0)])
    lo = firsts_moves[run] + np.maximum(local - half, 0)
    hi = firsts_moves[run] + np.minimum(local + half + 1, moves[run])
    smooth = (sums[hi] - sums[lo]) / np.maximum(hi - lo, 1)[:, None]
    speed = np.linalg.norm(smooth, axis=-1) * fps
    typical = np.nan_to_num(run_median(speed, run)) if run.size else np.zeros(0)
    planted = speed <= np.maximum(plant_speed, 1.5 * typical[run]) if run.size else speed > 0
    steady = np.stack(
        [np.nan_to_num(run_median(np.where(planted, own[:, k], np.nan), run)) for k in range(2)],
        axis=1,
    ) if run.size else np.zeros((0, 2))  # fmt: skip
    kept = np.where(planted[:, None], own, steady[run] if run.size else own)
    totals = np.concatenate([np.zeros((1, 2)), np.cumsum(kept, axis=0)])
    lengths = moves + 1
    firsts: IntArray = np.cumsum(lengths) - lengths
    row_run = np.repeat(np.arange(len(locks)), lengths)
    row_local = np.arange(int(lengths.sum())) - firsts[row_run]
    tracks: FloatArray = totals[firsts_moves[row_run] + row_local] - totals[firsts_moves[row_run]]
    return tracks, firsts


def planted_travel(
    steps: FloatArray, locks: Sequence[Lock], fps: float, plant_speed: float
) -> FloatArray:
    """Largest distance of each contact's :func:`planted_tracks` from its first frame, shape
    ``(L,)``, take units: the slide the lock removes."""
    if not locks:
        return np.zeros(0)
    tracks, firsts = planted_tracks(steps, locks, fps, plant_speed)
    travel: FloatArray = np.maximum.reduceat(np.linalg.norm(tracks, axis=-1), firsts)
    return travel


def lock_offsets(
    steps: FloatArray,
    locks: Sequence[Lock],
    fps: float,
    plant_speed: float,
    anchor: Anchor = "middle",
    blend_s: float = BLEND_S,
    first: int = 0,
) -> tuple[FloatArray, FloatArray]:
    """Horizontal ankle offsets that hold each locked contact's pivot at its anchor.

    Parameters
    ----------
    steps : ndarray, shape (F, 2, 2)
        :func:`pivot_steps`.
    locks : sequence of Lock
    fps : float
    plant_speed : float
        Take units per second (:func:`planted_tracks`).
    anchor : {"middle", "start"}
    blend_s : float
        Seconds of blend on either side of a contact.
    first : int
        Frames before this one (a bind pose) are never moved.

    Returns
    -------
    offsets : ndarray, shape (F, 2, 2)
        Per frame and foot, along the two horizontal axes, take units.
    weights : ndarray, shape (F, 2)
        Summed lock weights; frames with weight 0 are left alone.
    """
    n_frames = steps.shape[0]
    blend = max(1, round(blend_s * fps))
    total = np.zeros((n_frames, 2, 2))
    weights = np.zeros((n_frames, 2))
    if not locks:
        return total, weights
    tracks, firsts = planted_tracks(steps, locks, fps, plant_speed)
    starts = np.array([k.start for k in locks], dtype=np.intp)
    ends = np.array([k.end for k in locks], dtype=np.intp)
    feet = np.array([SIDES.index(k.foot) for k in locks], dtype=np.intp)
    lengths = ends - starts + 1
    if anchor == "middle":
        reference = tracks[firsts + (lengths - 1) // 2]
    else:
        head = np.minimum(lengths, blend)
        rows = (
            np.repeat(firsts, head)
            + np.arange(int(head.sum()))
            - np.repeat(np.cumsum(head) - head, head)
        )
        reference = np.add.reduceat(tracks[rows], np.cumsum(head) - head) / head[:, None]
    # Only the contacts and their blends: every other frame keeps weight 0.
    spans = lengths + 2 * blend
    lock = np.repeat(np.arange(len(locks)), spans)
    offset_in = np.arange(int(spans.sum())) - np.repeat(np.cumsum(spans) - spans, spans)
    frames = starts[lock] - blend + offset_in
    gap = np.maximum(starts[lock] - frames, frames - ends[lock])
    x = 1.0 - gap / (blend + 1.0)
    w = np.where(gap <= 0, 1.0, x * x * (3.0 - 2.0 * x))
    held = firsts[lock] + np.clip(frames, starts[lock], ends[lock]) - starts[lock]
    inside = (frames >= first) & (frames < n_frames)
    lock, frames, w, held = lock[inside], frames[inside], w[inside], held[inside]
    np.add.at(total, (frames, feet[lock]), w[:, None] * (reference[lock] - tracks[held]))
    np.add.at(weights, (frames, feet[lock]), w)
    offsets: FloatArray = total / np.maximum(weights, 1.0)[..., None]
    return offsets, weights
