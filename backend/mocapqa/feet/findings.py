"""Findings on planted and hovering feet: skate, penetration, floating and jitter.

Conventions
-----------
* Inputs are per point ``(F, P)`` or ``(F, P, 3)`` in take units, per foot masks ``(F, 2)``
  (left, right); sizes come back in take units (the caller converts them to centimetres)
  and thresholds are leg lengths (:class:`mocapqa.feet.params.FeetParams`).
* **Skate**: during a foot contact the foot's horizontal velocity is that of its slowest
  contacting point (the pivot: the heel at a heel strike, the toe at push-off, so a foot rolling
  over is not read as sliding, while a foot that slides moves every point); its displacement
  from the contact's first frame is integrated, and the largest distance reached is the
  travel. A contact whose travel reaches ``skate_travel`` is a skate; its speed is the travel
  over the contact's duration.
* **Penetration**: a point below its own stance level (the floor plus its offset) by more than
  ``penetration_depth`` plus the point's own spread at rest; the size is the depth of the
  deepest point of the foot in the run.
* **Floating**: a foot not in contact, all of its points slower than ``contact_speed``, its
  lowest point between ``contact_height`` and ``float_height`` above its stance level, for at
  least ``min_float_s``: a planted-looking foot that does not reach the floor. The size is its
  mean height above the floor over the phase.
* **Jitter**: frame-to-frame noise of a planted foot, ``|Δ²p|² / 6`` per frame (the second
  difference of white noise of RMS σ per axis has ``E|Δ²p|² = 6 · 3σ²``, while that of a still
  or smoothly rolling foot is near zero), its median over the contact's slow frames scaled to
  a mean; the RMS is reported at ``jitter_noise`` and above.
* Every finding has 0-based frames with an inclusive end and the frame of its peak.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, column_runs
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES, per_foot
from mocapqa.feet.runs import (
    Runs,
    close_short_gaps,
    drop_short_runs,
    frames_in,
    run_argmax,
    run_frames,
    run_mean,
    run_median,
)
from mocapqa.feet.sole import sole_sweep
from mocapqa.feet.tracks import norms

__all__ = [
    "FINDING_KINDS",
    "Finding",
    "find_floating",
    "find_jitter",
    "find_penetration",
    "find_skate",
    "foot_pair",
    "run_median",
    "side_members",
]

FINDING_KINDS = ("skate", "penetration", "floating", "jitter")
"""The kinds of finding, in the order they are listed."""
_CHI2_MEAN_OVER_MEDIAN = 3.0 / 2.366
"""Mean over median of a χ² variable with 3 degrees of freedom."""


@dataclass(frozen=True, slots=True)
class Finding:
    """One problem of one foot over a run of frames.

    Parameters
    ----------
    kind : str
        One of :data:`FINDING_KINDS`.
    foot : {"left", "right"}
    start, end : int
        First and last frame, 0-based, inclusive.
    size : float
        Take units: skate travel, penetration depth, floating height or jitter RMS.
    peak : int
        Frame where the size is reached (the deepest, farthest, noisiest).
    speed : float or None
        Skate only: travel over the contact's duration, take units per second.
    """

    kind: str
    foot: str
    start: int
    end: int
    size: float
    peak: int
    speed: float | None = None


def side_members(sides: tuple[str, ...]) -> BoolArray:
    """``(2, P)`` mask: which points belong to the left and to the right foot."""
    side_of = np.array([SIDES.index(s) for s in sides], dtype=np.intp)
    members: BoolArray = side_of[None, :] == np.arange(len(SIDES))[:, None]
    return members


def foot_pair(sides: tuple[str, ...]) -> tuple[IntArray, IntArray]:
    """Per foot (left, right), the index of its first point (the rear: heel or ankle) and of
    its last (the toe; the same point when the foot has one)."""
    rear = np.array([sides.index(s) for s in SIDES], dtype=np.intp)
    toe = np.array([len(sides) - 1 - sides[::-1].index(s) for s in SIDES], dtype=np.intp)
    return rear, toe


def _findings(
    kind: str, runs: Runs, sizes: FloatArray, peaks: IntArray, speeds: FloatArray | None = None
) -> list[Finding]:
    columns, starts, ends = runs
    return [
        Finding(
            kind, SIDES[int(columns[i])], int(starts[i]), int(ends[i]), float(sizes[i]),
            int(peaks[i]), None if speeds is None else float(speeds[i]),
        )
        for i in range(columns.size)
    ]  # fmt: skip


def find_skate(
    velocities: FloatArray,
    speeds: FloatArray,
    elevations: FloatArray,
    point_mask: BoolArray,
    foot_mask: BoolArray,
    sides: tuple[str, ...],
    horizontal: tuple[int, int],
    fps: float,
    leg_length: float,
    params: FeetParams | None = None,
    *,
    sole: tuple[FloatArray, FloatArray, UpAxis] | None = None,
) -> list[Finding]:
    """Horizontal travel of planted feet.

    Parameters
    ----------
    velocities : ndarray, shape (F, P, 3)
        Point velocities (of the smoothed tracks), take units per second.
    speeds : ndarray, shape (F, P)
        Their lengths.
    elevations : ndarray, shape (F, P)
        Heights above each point's stance level, take units.
    point_mask : ndarray of bool, shape (F, P)
        Point contacts.
    foot_mask : ndarray of bool, shape (F, 2)
        Foot contacts.
    sides : tuple of str
    horizontal : tuple of int
        The two horizontal axes.
    fps, leg_length, params
        Frames per second, the leg length (take units) and the thresholds (None: the
        defaults).
    sole : tuple, optional
        ``(positions, depths, up)``: the smoothed positions ``(F, P, 3)``, each point's
        height above the sole ``(F, P)`` (take units) and the up axis. The velocities are
        then those of the sole under each point (:mod:`mocapqa.feet.sole`), so a foot
        rolling over its heel or toe does not move; None reads the points themselves.

    Returns
    -------
    list of Finding
        Kind ``"skate"``; size is the travel (take units), speed travel per second.
    """
    p = params or FeetParams()
    runs = column_runs(foot_mask)
    if runs[0].size == 0:
        return []
    frame, column, run_index = run_frames(runs)
    lengths = runs[2] - runs[1] + 1
    firsts = np.cumsum(lengths) - lengths  # each run's first row in the concatenated order
    low = _low_points(elevations[frame], point_mask[frame], sides, column, run_index, firsts,
                      p.plant_height * leg_length)  # fmt: skip
    foot_velocity, pivot_speed = _pivot_velocity(
        velocities, horizontal, low, sides, frame, column, sole
    )
    # Planted: the pivot is slower than plant_speed, or than 1.5 times the contact's median
    # pivot speed, so a steady slide counts in full while the quick landing and push-off of
    # a clean contact do not.
    typical = run_median(np.where(np.isfinite(pivot_speed), pivot_speed, np.nan), run_index)
    limit = np.maximum(p.plant_speed * leg_length, 1.5 * typical[run_index])
    planted = pivot_speed < limit
    step = np.where(planted[:, None], np.nan_to_num(foot_velocity), 0.0)  # (N, 2)
    sizes, where = _travel(step, planted, run_index, firsts, lengths, fps, p.skate_window_s)
    flagged = sizes >= p.skate_travel * leg_length
    durations = np.maximum(lengths - 1, 1) / fps
    kept: Runs = (runs[0][flagged], runs[1][flagged], runs[2][flagged])
    return _findings(
        "skate", kept, sizes[flagged], frame[where][flagged], (sizes / durations)[flagged]
    )


def _travel(
    step: FloatArray,
    planted: BoolArray,
    run_index: IntArray,
    firsts: IntArray,
    lengths: IntArray,
    fps: float,
    window_s: float,
) -> tuple[FloatArray, IntArray]:
    """Travel of each contact ``(R,)`` (take units) and the row where it is reached, from the
    planted velocities ``step`` ``(N, 2)``: the larger of the displacement over any
    ``window_s`` (or since the contact's first frame) and the median planted velocity over
    the contact's duration (at most ``window_s``; a steady slide also moves the foot on the
    frames left out)."""
    totals = np.cumsum(step / fps, axis=0)
    lag = max(1, round(window_s * fps))
    since = np.maximum(np.arange(step.shape[0]) - lag, firsts[run_index])
    travel = norms(totals - totals[since])
    sizes, where = run_argmax(travel, run_index, lengths.size)
    steady_velocity = np.stack(
        [run_median(np.where(planted, step[:, k], np.nan), run_index) for k in range(2)], axis=1
    )
    steady = norms(np.nan_to_num(steady_velocity)) * np.minimum((lengths - 1) / fps, window_s)
    return np.maximum(sizes, steady), where


def _low_points(
    lift: FloatArray,
    in_contact: BoolArray,
    sides: tuple[str, ...],
    column: IntArray,
    run_index: IntArray,
    firsts: IntArray,
    plant_height: float,
) -> BoolArray:
    """Which points can carry the foot at each frame of each contact, ``(N, P)``.

    A point can carry the foot while in contact and within ``plant_height`` (take units) of
    its lowest height in this contact (the local floor, so a drifting floor does not count):
    a heel or toe rising at push-off rolls over, it does not slide. ``lift`` and
    ``in_contact`` are the elevations and point contacts at the contacts' frames, ``(N, P)``.
    """
    lowest = np.minimum.reduceat(np.where(np.isfinite(lift), lift, np.inf), firsts, axis=0)
    with np.errstate(invalid="ignore"):
        low: BoolArray = (
            side_members(sides)[column] & in_contact & (lift - lowest[run_index] < plant_height)
        )
    return low


def _pivot_velocity(
    velocities: FloatArray,
    horizontal: tuple[int, int],
    low: BoolArray,
    sides: tuple[str, ...],
    frame: IntArray,
    column: IntArray,
    sole: tuple[FloatArray, FloatArray, UpAxis] | None,
) -> tuple[FloatArray, FloatArray]:
    """The foot's horizontal velocity ``(N, 2)`` and the pivot's speed ``(N,)`` (inf where no
    point is low).

    The foot's velocity is that of its least-moving low point: on the line from the rear
    point (heel or ankle) to the toe when both are low (velocities of a rigid foot vary
    linearly along it, so a foot rolling over its toe, or turning about its ball or its
    midfoot, has a point there that stays), else the one low point. With ``sole`` (as in
    :func:`find_skate`) the points are those of the sole under the rear point and the toe.
    """
    rear, toe = foot_pair(sides)
    rows = np.arange(frame.size)
    rear_velocity = velocities[frame, rear[column]]
    toe_velocity = velocities[frame, toe[column]]
    if sole is not None:
        positions, depths, up = sole
        sweep = sole_sweep(
            positions[frame, toe[column]] - positions[frame, rear[column]],
            toe_velocity - rear_velocity,
            up,
        )
        drop = np.clip(np.nan_to_num(depths, nan=0.0), 0.0, None)
        rear_velocity = rear_velocity - drop[frame, rear[column], None] * sweep
        toe_velocity = toe_velocity - drop[frame, toe[column], None] * sweep
    rear_velocity = rear_velocity[:, list(horizontal)]
    toe_velocity = toe_velocity[:, list(horizontal)]
    rear_low = low[rows, rear[column]]
    toe_low = low[rows, toe[column]]
    span = toe_velocity - rear_velocity
    with np.errstate(invalid="ignore", divide="ignore"):
        share = -np.einsum("nk,nk->n", rear_velocity, span) / np.einsum("nk,nk->n", span, span)
    share = np.where(rear_low & toe_low, np.clip(np.nan_to_num(share), 0.0, 1.0),
                     np.where(toe_low, 1.0, 0.0))  # fmt: skip
    foot_velocity: FloatArray = rear_velocity + share[:, None] * span
    pivot_speed: FloatArray = np.where(rear_low | toe_low, norms(foot_velocity), np.inf)
    return foot_velocity, pivot_speed


def find_penetration(
    elevations: FloatArray,
    spreads: FloatArray,
    sides: tuple[str, ...],
    fps: float,
    leg_length: float,
    params: FeetParams | None = None,
) -> list[Finding]:
    """Runs where a foot is below the floor.

    Parameters
    ----------
    elevations, sides, fps, leg_length, params
        As in :func:`find_skate`.
    spreads : ndarray, shape (P,)
        How much each point's height varies at rest (:attr:`Floor.point_spreads`), take units:
        a point is below the floor when deeper than ``penetration_depth`` plus its spread (an
        ankle joint sinks and rises by a centimetre on a planted foot by itself; a toe or a
        heel marker barely moves).

    Returns
    -------
    list of Finding
        Kind ``"penetration"``; size is the largest depth (take units).
    """
    p = params or FeetParams()
    depth_points = np.where(np.isfinite(elevations), -elevations, -np.inf)
    excess = per_foot(depth_points - spreads, sides, np.maximum)
    depth = per_foot(depth_points, sides, np.maximum)
    mask = close_short_gaps(excess > p.penetration_depth * leg_length, frames_in(p.max_gap_s, fps))
    runs = column_runs(mask)
    if runs[0].size == 0:
        return []
    frame, column, run_index = run_frames(runs)
    sizes, where = run_argmax(depth[frame, column], run_index, runs[0].size)
    return _findings("penetration", runs, sizes, frame[where])


def find_floating(
    elevations: FloatArray,
    speeds: FloatArray,
    foot_mask: BoolArray,
    sides: tuple[str, ...],
    fps: float,
    leg_length: float,
    params: FeetParams | None = None,
) -> list[Finding]:
    """Still feet hovering just above the floor, out of contact.

    Parameters
    ----------
    elevations, speeds, foot_mask, sides, fps, leg_length, params
        As in :func:`find_skate`.

    Returns
    -------
    list of Finding
        Kind ``"floating"``; size is the mean height of the foot's lowest point above its
        stance level (take units).
    """
    p = params or FeetParams()
    lowest = per_foot(np.where(np.isfinite(elevations), elevations, np.inf), sides, np.minimum)
    fastest = per_foot(np.where(np.isfinite(speeds), speeds, np.inf), sides, np.maximum)
    hovering = (
        ~foot_mask
        & (fastest < p.contact_speed * leg_length)
        & (lowest > p.contact_height * leg_length)
        & (lowest <= p.float_height * leg_length)
    )
    mask = drop_short_runs(
        close_short_gaps(hovering, frames_in(p.max_gap_s, fps)), frames_in(p.min_float_s, fps)
    )
    runs = column_runs(mask)
    if runs[0].size == 0:
        return []
    frame, column, run_index = run_frames(runs)
    _, where = run_argmax(lowest[frame, column], run_index, runs[0].size)
    sizes = run_mean(np.where(np.isfinite(lowest), lowest, np.nan), runs)
    return _findings("floating", runs, sizes, frame[where])


def find_jitter(
    positions: FloatArray,
    speeds: FloatArray,
    point_mask: BoolArray,
    foot_mask: BoolArray,
    sides: tuple[str, ...],
    leg_length: float,
    params: FeetParams | None = None,
) -> list[Finding]:
    """Noise of planted feet.

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
        Raw (unsmoothed) point positions, take units.
    speeds : ndarray, shape (F, P)
        Speeds of the smoothed tracks, take units per second: only frames where a point is
        in contact and slower than ``contact_speed`` count (a landing's deceleration is
        motion, not noise).
    point_mask : ndarray of bool, shape (F, P)
    foot_mask : ndarray of bool, shape (F, 2)
    sides : tuple of str
    leg_length : float
    params : FeetParams, optional

    Returns
    -------
    list of Finding
        Kind ``"jitter"``; size is the RMS noise (take units) over the contact, from the
        median second-difference power (× 1.27, the mean over the median of a χ² with 3
        degrees of freedom), so a few frames of real acceleration do not make it.
    """
    p = params or FeetParams()
    n_frames = positions.shape[0]
    power = np.full(point_mask.shape, np.nan)
    if n_frames >= 3:
        second = positions[2:] - 2.0 * positions[1:-1] + positions[:-2]
        power[1:-1] = np.einsum("fpk,fpk->fp", second, second) / 6.0
    with np.errstate(invalid="ignore"):
        used = point_mask & np.isfinite(power) & (speeds < p.contact_speed * leg_length)
    counts = per_foot(used.astype(np.float64), sides, np.add)
    sums = per_foot(np.where(used, power, 0.0), sides, np.add)
    with np.errstate(invalid="ignore", divide="ignore"):
        noise = np.where(counts > 0, sums / np.maximum(counts, 1.0), np.nan)  # (F, 2)
    runs = column_runs(foot_mask)
    if runs[0].size == 0:
        return []
    frame, column, run_index = run_frames(runs)
    rms = np.sqrt(_CHI2_MEAN_OVER_MEDIAN * run_median(noise[frame, column], run_index))
    with np.errstate(invalid="ignore"):
        flagged = rms >= p.jitter_noise * leg_length
    kept: Runs = (runs[0][flagged], runs[1][flagged], runs[2][flagged])
    if kept[0].size == 0:
        return []
    frame, column, run_index = run_frames(kept)
    _, where = run_argmax(noise[frame, column], run_index, kept[0].size)
    return _findings("jitter", kept, rms[flagged], frame[where])
