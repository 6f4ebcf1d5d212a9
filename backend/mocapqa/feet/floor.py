"""The floor under a take, from its feet: level, each point's offset, tilt and drift.

Conventions
-----------
* Heights are along the up axis (:class:`mocapqa.feet.ground.UpAxis`), take units.
* The floor is the level of the lowest foot point at rest: every point has its own stance
  level (where its still heights cluster most, :func:`stance_levels`), the floor is the
  lowest of those, and each point keeps its offset above it (an ankle joint sits ~8 cm above
  the floor, a toe joint ~2 cm). Joint centres are not the sole, so the floor of a BVH take
  lies a few centimetres above the surface the performer stood on; keypoint takes with heel
  and toe markers are close.
* Tilt and drift are measured, not assumed away. A plane fitted where each foot stood still
  (robust least squares, each foot centred on its own means, only along directions the feet
  covered) gives the tilt and the rise across the area stood on; the level per segment of the
  take gives the drift over time. A straight walk at a steady pace cannot tell a tilt from a
  drift (position and time go together): the plane takes it, and the take is reported
  tilted. :func:`mocapqa.feet.check.check_feet` then measures heights from the reported plane.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.errors import InputError
from mocapqa.feet.ground import MIN_STILL_SAMPLES, sample_stride
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES

__all__ = ["Floor", "column_percentile", "fit_floor", "stance_levels"]

_FLOOR_BAND = 0.1
"""Still samples this many leg lengths (9 cm for a 90 cm leg) or less above a point's stance
level measure the floor's tilt and drift."""


@dataclass(frozen=True, slots=True)
class Floor:
    """The floor under a take, measured from its feet.

    Parameters
    ----------
    level : float
        Height of the floor along the up direction, take units (the coordinate on the up
        axis is ``sign × level``).
    point_offsets : ndarray, shape (P,)
        Each point's stance level above the floor, take units.
    point_spreads : ndarray, shape (P,)
        Interquartile range of each point's heights at rest, take units: how much a joint
        centre such as the ankle rises and drops on a planted foot by itself.
    tilt_deg : float or None
        Slope of the plane fitted to the stance samples, degrees; None when the feet stood
        on too small an area (under half a leg length across) to tell.
    rise : float or None
        Height change of that plane across the area stood on, take units.
    drift : float
        Range of the floor level over the segments of the take (after the plane when the
        floor is tilted), take units.
    tilted, moving : bool
        Whether tilt and rise, or drift, exceed their tolerances.
    segments : tuple of (int, int, float)
        First frame, last frame and floor level (along up, take units) of each segment with
        enough stance samples.
    n_samples : int
        Stance samples the floor was measured on.
    gradient : tuple of float, optional
        Slope of the fitted plane along the two horizontal axes (height per unit), when one
        was measured.
    origin : tuple of float
        Horizontal position at which the plane is at ``level`` (the mean of the stance
        samples).
    """

    level: float
    point_offsets: FloatArray
    point_spreads: FloatArray
    tilt_deg: float | None
    rise: float | None
    drift: float
    tilted: bool
    moving: bool
    segments: tuple[tuple[int, int, float], ...]
    n_samples: int
    gradient: tuple[float, float] | None = None
    origin: tuple[float, float] = (0.0, 0.0)

    def plane(self, horizontal: FloatArray) -> FloatArray:
        """Height of the fitted floor plane above ``level`` at ``horizontal`` ``(..., 2)``
        (zeros when the floor is not tilted)."""
        xy = np.asarray(horizontal, dtype=np.float64)
        if not self.tilted or self.gradient is None:
            return np.zeros(xy.shape[:-1])
        heights: FloatArray = (xy - np.asarray(self.origin)) @ np.asarray(self.gradient)
        return heights


def stance_levels(
    heights: FloatArray, static: BoolArray, percentile: float, band: float
) -> FloatArray:
    """Each point's stance level: the median of its still heights in the densest window
    ``band`` tall (the level the point rests at most of the time), or ``percentile`` of all
    its heights when it is still in fewer than 5 frames.

    The densest window rather than a low percentile: a foot sunk into the floor for a fifth of
    a take would pull a 20th percentile down to its depth (and hide the depth), and a foot
    held still in the air would lift a median; the window stays with the majority either way,
    as long as the foot rests at its true level more than at any other.

    Parameters
    ----------
    heights : ndarray, shape (F, P)
        Take units; NaN where missing.
    static : ndarray of bool, shape (F, P)
    percentile : float
        0–100, for points that are hardly ever still.
    band : float
        Height of the window, take units.

    Returns
    -------
    ndarray, shape (P,)
        Take units (NaN for a point with no value at all).
    """
    return _stance_band(heights, static, percentile, band)[0]


def _stance_band(
    heights: FloatArray, static: BoolArray, percentile: float, band: float
) -> tuple[FloatArray, FloatArray]:
    """:func:`stance_levels` and the interquartile range of the heights in each point's
    densest window (0 for a point that is hardly ever still)."""
    still = static & np.isfinite(heights)
    n_points = heights.shape[1]
    levels = column_percentile(heights, np.isfinite(heights), percentile)
    spreads = np.zeros(n_points)
    for p in range(n_points):  # a handful of points; each step is vectorised over frames
        values = np.sort(heights[still[:, p], p])
        if values.size < MIN_STILL_SAMPLES:
            continue
        ends = np.searchsorted(values, values + band, side="right")
        first = int(np.argmax(ends - np.arange(values.size)))
        window = values[first : ends[first]]
        levels[p] = float(np.median(window))
        low, high = np.percentile(window, [25.0, 75.0])
        spreads[p] = float(high - low)
    return levels, spreads


def column_percentile(values: FloatArray, mask: BoolArray, percentile: float) -> FloatArray:
    """``percentile`` (0–100, linear interpolation as :func:`numpy.percentile`) of each
    column of ``values`` ``(F, P)`` over the rows where ``mask`` holds; NaN for a column
    with no such row. One sort of the whole array instead of a call per column."""
    ordered = np.sort(np.where(mask, values, np.inf), axis=0)
    counts = mask.sum(axis=0)
    position = (np.maximum(counts, 1) - 1) * (percentile / 100.0)
    below = np.floor(position).astype(np.intp)
    above = np.minimum(below + 1, np.maximum(counts - 1, 0))
    columns = np.arange(values.shape[1])
    low, high = ordered[below, columns], ordered[above, columns]
    with np.errstate(invalid="ignore"):
        result: FloatArray = np.where(counts > 0, low + (high - low) * (position - below), np.nan)
    return result


def _plane(
    samples: FloatArray, heights: FloatArray, feet: IntArray, min_extent: float
) -> tuple[FloatArray | None, FloatArray, float]:
    """Robust slope of the floor: ``h − mean_foot(h) = g · (xy − mean_foot(xy))``.

    Each foot is centred on its own means, so the slope comes from how the floor under one
    foot changes as it stands in different places, never from the difference between the two
    feet's offsets above it (they stand apart sideways, and an intercept per foot would leave
    that direction to chance). The slope is measured only along the principal directions in
    which the feet stood over at least ``min_extent`` (5th–95th percentile), and taken as
    zero across them: a straight walk tells the slope along the path, not across it. Least
    squares, then again without the samples beyond 3 robust standard deviations.

    Returns
    -------
    gradient : ndarray, shape (2,), or None
        None when no direction is wide enough.
    residuals : ndarray, shape (N,)
        Heights less each foot's fitted plane, plus the mean height (``heights`` when there
        is no gradient).
    extent : float
        The widest extent, take units.
    """
    n_feet = int(feet.max()) + 1
    counts = np.maximum(np.bincount(feet, minlength=n_feet), 1)
    centred_xy = (
        samples
        - np.stack([np.bincount(feet, samples[:, k], n_feet) / counts for k in range(2)], axis=1)[
            feet
        ]
    )
    centred_h = heights - (np.bincount(feet, heights, n_feet) / counts)[feet]
    directions = np.linalg.svd(centred_xy, full_matrices=False)[2]  # rows: principal axes
    along = centred_xy @ directions.T
    extents = np.percentile(along, 95, axis=0) - np.percentile(along, 5, axis=0)
    wide = extents >= min_extent
    if not wide.any():
        return None, heights, float(extents.max())
    design = along[:, wide]
    coef = np.asarray(np.linalg.lstsq(design, centred_h, rcond=None)[0], dtype=np.float64)
    residuals = centred_h - design @ coef
    mad = 1.4826 * np.median(np.abs(residuals - np.median(residuals)))
    keep = np.abs(residuals) <= max(3.0 * mad, 1e-12)
    if keep.sum() >= 3 and not keep.all():
        coef = np.asarray(
            np.linalg.lstsq(design[keep], centred_h[keep], rcond=None)[0], dtype=np.float64
        )
    gradient: FloatArray = coef @ directions[wide]
    # Residuals about each foot's own plane, around the overall mean height: their level per
    # segment of the take is the drift left once the slope is accounted for.
    fitted_residuals: FloatArray = centred_h - centred_xy @ gradient + float(np.mean(heights))
    return gradient, fitted_residuals, float(extents.max())


def _segment_percentile(
    values: FloatArray, segment: IntArray, min_count: int, percentile: float
) -> FloatArray:
    """``percentile`` (nearest lower rank) of ``values`` per segment index; NaN for segments
    with fewer than ``min_count`` values."""
    n_segments = int(segment.max()) + 1 if segment.size else 0
    counts = np.bincount(segment, minlength=n_segments)
    order = np.lexsort((values, segment))
    first = np.concatenate(([0], np.cumsum(counts)[:-1]))
    rank = first + (np.maximum(counts - 1, 0) * percentile / 100.0).astype(np.intp)
    picked = values[order][np.minimum(rank, max(len(values) - 1, 0))] if values.size else values
    out: FloatArray = np.where(counts >= min_count, picked, np.nan)
    return out


@dataclass(frozen=True, slots=True)
class _Stance:
    """The lowest point of each foot per frame, and its samples near the floor at rest.

    Attributes
    ----------
    lowest : ndarray of int, shape (F, 2)
        Per frame and foot, the point whose floor (height less offset) is lowest.
    foot_sole : ndarray, shape (F, 2)
        Where the floor would be under that point, take units (inf where missing).
    sample_rows, sample_feet : ndarray of int, shape (N,)
        Frame (of the sampled frames) and foot of each stance sample.
    """

    lowest: IntArray
    foot_sole: FloatArray
    sample_rows: IntArray
    sample_feet: IntArray

    @property
    def values(self) -> FloatArray:
        """The floor under each stance sample, shape (N,), take units."""
        values: FloatArray = self.foot_sole[self.sample_rows, self.sample_feet]
        return values

    @property
    def sample_points(self) -> IntArray:
        """The point of each stance sample, shape (N,)."""
        points: IntArray = self.lowest[self.sample_rows, self.sample_feet]
        return points

    def still(self, static: BoolArray) -> BoolArray:
        """Where each foot's lowest point is still and has a height, shape (F, 2)."""
        rows = np.arange(self.lowest.shape[0])[:, None]
        still: BoolArray = static[rows, self.lowest] & np.isfinite(self.foot_sole)
        return still


def _stance_samples(
    heights: FloatArray,
    static: BoolArray,
    sides: tuple[str, ...],
    level: float,
    offsets: FloatArray,
    leg_length: float,
) -> _Stance:
    """Per foot and frame the lowest of its points (a heel rising at push-off, or on tiptoe,
    says nothing about the floor: the toe does), and the still samples up to
    ``_FLOOR_BAND`` leg lengths above the floor: wide enough to keep a floor that rises or
    drops by several centimetres (the thing measured), narrow enough to leave out a foot held
    still in the air or resting on a step."""
    sole = np.where(np.isfinite(heights), heights - offsets, np.inf)
    side_of = np.array([SIDES.index(side) for side in sides], dtype=np.intp)
    feet = [np.flatnonzero(side_of == k) for k in range(len(SIDES))]
    lowest = np.stack([f[np.argmin(sole[:, f], axis=1)] for f in feet], axis=1)  # (F, 2)
    rows = np.arange(heights.shape[0])[:, None]
    foot_sole = sole[rows, lowest]
    stance = (
        static[rows, lowest]
        & np.isfinite(foot_sole)
        & (foot_sole - level < _FLOOR_BAND * leg_length)
    )
    sample_rows, sample_feet = np.nonzero(stance)
    return _Stance(lowest, foot_sole, sample_rows, sample_feet)


@dataclass(frozen=True, slots=True)
class _Tilt:
    """The floor plane: slope, rise, whether tilted, and the residuals the drift is read on."""

    tilt_deg: float | None
    rise: float | None
    tilted: bool
    gradient: tuple[float, float] | None
    residuals: FloatArray


def _tilt(
    stance: _Stance,
    xy: FloatArray,
    static: BoolArray,
    horizontal: FloatArray,
    level: float,
    leg_length: float,
    p: FeetParams,
) -> _Tilt:
    """Fit the floor plane to the stance samples (:func:`_plane`) when there are enough."""
    values = stance.values
    residuals = values - level
    if values.size < 3 * MIN_STILL_SAMPLES:
        return _Tilt(None, None, False, None, residuals)
    gradient, plane_residuals, _ = _plane(xy, values, stance.sample_feet, 0.5 * leg_length)
    if gradient is None:
        return _Tilt(None, None, False, None, residuals)
    slope = float(np.linalg.norm(gradient))
    tilt_deg = float(np.degrees(np.arctan(slope)))
    if slope > 0:
        # Across everywhere the feet stood still, not only the samples near the floor level
        # that measured the slope: a steep floor rises beyond that band.
        still = stance.still(static)
        stood = horizontal[np.nonzero(still)[0], stance.lowest[still]]
        uphill = stood @ (gradient / slope)
        rise = slope * float(np.percentile(uphill, 95) - np.percentile(uphill, 5))
    else:
        rise = 0.0
    tilted = tilt_deg > p.floor_tilt_deg and rise > p.floor_rise * leg_length
    return _Tilt(
        tilt_deg,
        rise,
        tilted,
        (float(gradient[0]), float(gradient[1])),
        plane_residuals if tilted else residuals,
    )


def _drift(
    values: FloatArray,
    residuals: FloatArray,
    tilted: bool,
    frames: IntArray,
    n_frames: int,
    fps: float,
    stride: int,
    p: FeetParams,
) -> tuple[float, tuple[tuple[int, int, float], ...]]:
    """The range of the floor level over the segments of the take, and the segments."""
    segment_frames = max(1, round(p.floor_segment_s * fps))
    n_segments = max(1, round(n_frames / segment_frames))
    bounds = np.linspace(0, n_frames, n_segments + 1).round().astype(np.intp)
    segment_of = np.searchsorted(bounds, frames, side="right") - 1
    min_count = max(3, round(0.1 * fps / stride))
    raw = _segment_percentile(values, segment_of, min_count, 50.0)
    drift_levels = _segment_percentile(residuals, segment_of, min_count, 50.0) if tilted else raw
    finite = drift_levels[np.isfinite(drift_levels)]
    drift = float(np.ptp(finite)) if finite.size >= 2 else 0.0
    segments = tuple(
        (int(bounds[s]), int(bounds[s + 1]) - 1, float(raw[s]))
        for s in range(raw.size)
        if np.isfinite(raw[s])
    )
    return drift, segments


def fit_floor(
    heights: FloatArray,
    horizontal: FloatArray,
    static: BoolArray,
    sides: tuple[str, ...],
    fps: float,
    leg_length: float,
    params: FeetParams | None = None,
) -> Floor:
    """Measure the floor: its level, each point's offset above it, its tilt and its drift.

    Parameters
    ----------
    heights : ndarray, shape (F, P)
        Heights of the foot points along the up direction, take units.
    horizontal : ndarray, shape (F, P, 2)
        Their two horizontal coordinates, take units.
    static : ndarray of bool, shape (F, P)
        Where each point is still.
    sides : tuple of str
        The foot of each point.
    fps, leg_length, params
        Frames per second, the leg length (take units) and the thresholds (None: the
        defaults).

    Returns
    -------
    Floor

    Raises
    ------
    InputError
        If no foot point has a height.
    """
    p = params or FeetParams()
    n_frames = heights.shape[0]
    stride = sample_stride(n_frames)
    heights, horizontal, static = heights[::stride], horizontal[::stride], static[::stride]
    levels, spreads = _stance_band(
        heights, static, p.stance_percentile, 0.5 * p.contact_height * leg_length
    )
    if not np.any(np.isfinite(levels)):
        raise InputError("Expected foot points with heights, got none")
    level = float(np.nanmin(levels))
    offsets: FloatArray = np.where(np.isfinite(levels), levels - level, np.nan)
    stance = _stance_samples(heights, static, sides, level, offsets, leg_length)
    values = stance.values
    xy = horizontal[stance.sample_rows, stance.sample_points]
    origin = (float(np.mean(xy[:, 0])), float(np.mean(xy[:, 1]))) if xy.size else (0.0, 0.0)
    tilt = _tilt(stance, xy, static, horizontal, level, leg_length, p)
    drift, segments = _drift(
        values, tilt.residuals, tilt.tilted, stance.sample_rows * stride, n_frames, fps, stride, p
    )
    return Floor(
        level=level,
        point_offsets=offsets,
        point_spreads=spreads,
        tilt_deg=tilt.tilt_deg,
        rise=tilt.rise,
        drift=drift,
        tilted=bool(tilt.tilted),
        moving=bool(drift > p.floor_drift * leg_length),
        segments=segments,
        n_samples=int(values.size),
        gradient=tilt.gradient,
        origin=origin,
    )
