"""The up axis and the floor of a take, from its feet.

Conventions
-----------
* The up axis is one of the take's coordinate axes with a sign (``"Y"`` is +Y up, ``"-Y"`` is
  Y pointing down, as in MediaPipe's world landmarks and image coordinates). Heights are
  coordinates along it: ``sign × positions[..., axis]``, take units.
* Two cues choose it. **Feet**: along the up axis the foot points come back to the same level
  whenever they are still, while along a horizontal axis their still positions differ from
  step to step and between the left and the right foot; the feet cue is the axis with the
  smallest spread (10th–90th percentile) of still positions, pooled over both feet per part,
  and it is decisive when that spread is under half the next smallest. **Body**
  (gravity-free): in any upright motion the pelvis sits about a leg length above the feet, so
  the median pelvis-minus-feet vector points up. The body cue decides when it is clear (within
  about 25° of an axis and at least half a leg length long): on the corpus the feet cue alone
  picked a horizontal axis for short straight runs (too few still frames; the feet stay on
  one line, so the lateral axis varies least) and for a walk down uneven ground, and the body
  cue never erred on an upright take. Otherwise the feet cue decides (method ``"feet"``, or
  ``"weak"`` when it is not decisive either). The sign is the pelvis' side; without a clear
  pelvis, the side on which ankles and heels sit above toes. Neither cue uses gravity or
  accelerations, and neither holds for a take lying down or upside down the whole time; the
  report names the cue that decided.
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

import warnings
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.errors import InputError
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES

__all__ = [
    "AXIS_NAMES",
    "SAMPLE_FRAMES",
    "Floor",
    "UpAxis",
    "column_percentile",
    "detect_up_axis",
    "fit_floor",
    "sample_stride",
    "stance_levels",
]

AXIS_NAMES = ("X", "Y", "Z")
"""Coordinate axis names, by index."""
_DECISIVE = 0.5
"""The feet cue decides when its smallest spread is under this share of the next smallest."""
_BODY_DOMINANCE = 0.9
"""The body cue decides when the pelvis-over-feet direction is this close to an axis (cosine,
about 25°) ..."""
_BODY_LIFT = 0.5
"""... and the pelvis sits at least this many leg lengths above the feet along it."""
_MIN_SAMPLES = 5
_FLOOR_BAND = 0.1
"""Still samples this many leg lengths (9 cm for a 90 cm leg) or less above a point's stance
level measure the floor's tilt and drift."""
SAMPLE_FRAMES = 4000
"""The up axis and the floor are measured on at most about this many frames, evenly spread:
percentiles and a plane over 4,000 frames of four points are as good as over all of a long
take, and the check's cost stays linear in the rest of its steps."""


def sample_stride(n_frames: int) -> int:
    """Every how many frames the up axis and the floor take a sample (1 up to
    :data:`SAMPLE_FRAMES` frames)."""
    return max(1, -(-n_frames // SAMPLE_FRAMES))


@dataclass(frozen=True, slots=True)
class UpAxis:
    """The up direction of a take.

    Parameters
    ----------
    axis : int
        0, 1 or 2 (X, Y, Z).
    sign : int
        +1 when up is the positive direction of the axis, −1 when it is the negative one.
    method : str
        Which cue decided: ``"feet and body"`` (both agree), ``"feet"``, ``"body"`` or
        ``"weak"`` (neither was decisive; the smallest feet spread was taken).
    feet_spreads : tuple of float
        Spread of the still foot positions along X, Y and Z, leg lengths (inf for an axis
        the points do not use, such as Z of 2D keypoints).
    body_axis : int or None
        The axis closest to the pelvis-over-feet direction, None without a pelvis.
    """

    axis: int
    sign: int
    method: str
    feet_spreads: tuple[float, float, float]
    body_axis: int | None = None

    @property
    def label(self) -> str:
        """``"Y"`` for +Y up, ``"-Z"`` for −Z up, and so on."""
        return ("" if self.sign > 0 else "-") + AXIS_NAMES[self.axis]

    def heights(self, positions: FloatArray) -> FloatArray:
        """Heights along the up direction, shape ``positions.shape[:-1]``, take units."""
        heights: FloatArray = self.sign * np.asarray(positions, dtype=np.float64)[..., self.axis]
        return heights


def detect_up_axis(
    positions: FloatArray,
    parts: tuple[str, ...],
    static: BoolArray,
    leg_length: float,
    pelvis: FloatArray | None = None,
) -> UpAxis:
    """Find the up axis from where the feet rest and where the body is.

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
        Foot point positions, take units; NaN where missing.
    parts : tuple of str
        The part of each point (``"heel"``, ``"ankle"``, ``"toe"``).
    static : ndarray of bool, shape (F, P)
        Where each point is still.
    leg_length : float
        Take units.
    pelvis : ndarray, shape (F, 3), optional
        A body point above the feet.

    Returns
    -------
    UpAxis

    Raises
    ------
    InputError
        If the foot points have no usable coordinates.
    """
    stride = sample_stride(positions.shape[0])
    positions, static = positions[::stride], static[::stride]
    pelvis = None if pelvis is None else pelvis[::stride]
    if np.sum(np.isfinite(positions).all(axis=-1).any(axis=-1)) < 2:
        raise InputError("Expected foot points with positions in at least 2 frames, got fewer")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        extent = np.nanmax(positions, axis=(0, 1)) - np.nanmin(positions, axis=(0, 1))
    used = extent > 1e-9 * leg_length
    groups = [[p for p, q in enumerate(parts) if q == part] for part in dict.fromkeys(parts)]
    per_group = []
    for members in groups:
        values = positions[:, members].reshape(-1, 3)
        still = static[:, members].ravel()
        samples = values[still] if still.sum() >= _MIN_SAMPLES else values
        samples = samples[np.isfinite(samples).all(axis=-1)]
        if samples.shape[0] < 2:
            per_group.append(np.full(3, np.inf))
            continue
        low, high = np.percentile(samples, [10.0, 90.0], axis=0)
        per_group.append(high - low)
    spread = np.where(used, np.mean(per_group, axis=0) / leg_length, np.inf)
    spreads = [float(v) for v in spread]
    order = np.argsort(spreads)
    feet_axis = int(order[0])
    decisive = spreads[order[0]] < _DECISIVE * spreads[order[1]]
    body_axis: int | None = None
    body = None
    if pelvis is not None:
        with warnings.catch_warnings():
            # Frames without any foot point (a keypoint take's gaps) are NaN, not a warning.
            warnings.simplefilter("ignore", RuntimeWarning)
            body = np.nanmedian(pelvis - np.nanmean(positions, axis=1), axis=0)
        if np.all(np.isfinite(body)):
            body = np.where(used, body, 0.0)
            body_axis = int(np.argmax(np.abs(body)))
        else:
            body = None
    upright = (
        body is not None
        and body_axis is not None
        and abs(body[body_axis]) >= _BODY_DOMINANCE * np.linalg.norm(body)
        and abs(body[body_axis]) >= _BODY_LIFT * leg_length
    )
    if upright and body_axis is not None:
        axis = body_axis
        method = "feet and body" if decisive and feet_axis == axis else "body"
    elif decisive:
        axis, method = feet_axis, "feet"
    else:
        axis, method = feet_axis, "weak"
    sign = _sign(positions, parts, axis, body, leg_length)
    return UpAxis(axis, sign, method, (spreads[0], spreads[1], spreads[2]), body_axis)


def _sign(
    positions: FloatArray,
    parts: tuple[str, ...],
    axis: int,
    body: FloatArray | None,
    leg_length: float,
) -> int:
    """+1 or −1: the pelvis is above the feet, else ankles and heels are above toes."""
    if body is not None and abs(body[axis]) > 0.25 * leg_length:
        return 1 if body[axis] > 0 else -1
    toes = [p for p, part in enumerate(parts) if part == "toe"]
    rears = [p for p, part in enumerate(parts) if part != "toe"]
    if toes and rears:
        lift = np.nanmedian(
            np.nanmean(positions[:, rears, axis], axis=1)
            - np.nanmean(positions[:, toes, axis], axis=1)
        )
        if np.isfinite(lift) and lift != 0:
            return 1 if lift > 0 else -1
    return 1


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
        if values.size < _MIN_SAMPLES:
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
    fps : float
    leg_length : float
        Take units.
    params : FeetParams, optional

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
    # Where the floor would be under each point; per foot and frame, the lowest of its points
    # (a heel rising at push-off, or on tiptoe, says nothing about the floor: the toe does).
    sole = np.where(np.isfinite(heights), heights - offsets, np.inf)
    side_of = np.array([SIDES.index(side) for side in sides], dtype=np.intp)
    feet = [np.flatnonzero(side_of == k) for k in range(len(SIDES))]
    lowest = np.stack([f[np.argmin(sole[:, f], axis=1)] for f in feet], axis=1)  # (F, 2)
    rows = np.arange(heights.shape[0])[:, None]
    foot_sole = sole[rows, lowest]
    # Still samples up to _FLOOR_BAND leg lengths above the floor: wide enough to keep a floor
    # that rises or drops by several centimetres (the thing measured here), narrow enough to
    # leave out a foot held still in the air or resting on a step.
    stance = (
        static[rows, lowest]
        & np.isfinite(foot_sole)
        & (foot_sole - level < _FLOOR_BAND * leg_length)
    )
    sample_rows, sample_feet = np.nonzero(stance)
    frames = sample_rows * stride
    values = foot_sole[sample_rows, sample_feet]
    xy = horizontal[sample_rows, lowest[sample_rows, sample_feet]]
    tilt_deg: float | None = None
    rise: float | None = None
    tilted = False
    plane_gradient: tuple[float, float] | None = None
    origin = (float(np.mean(xy[:, 0])), float(np.mean(xy[:, 1]))) if xy.size else (0.0, 0.0)
    residuals = values - level
    if values.size >= 3 * _MIN_SAMPLES:
        gradient, plane_residuals, _ = _plane(xy, values, sample_feet, 0.5 * leg_length)
        if gradient is not None:
            plane_gradient = (float(gradient[0]), float(gradient[1]))
            slope = float(np.linalg.norm(gradient))
            tilt_deg = float(np.degrees(np.arctan(slope)))
            if slope > 0:
                # Across everywhere the feet stood still, not only the samples near the floor
                # level that measured the slope: a steep floor rises beyond that band.
                still = static[rows, lowest] & np.isfinite(foot_sole)
                stood = horizontal[np.nonzero(still)[0], lowest[still]]
                uphill = stood @ (gradient / slope)
                rise = slope * float(np.percentile(uphill, 95) - np.percentile(uphill, 5))
            else:
                rise = 0.0
            tilted = tilt_deg > p.floor_tilt_deg and rise > p.floor_rise * leg_length
            if tilted:
                residuals = plane_residuals
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
    return Floor(
        level=level,
        point_offsets=offsets,
        point_spreads=spreads,
        tilt_deg=tilt_deg,
        rise=rise,
        drift=drift,
        tilted=bool(tilted),
        moving=bool(drift > p.floor_drift * leg_length),
        segments=segments,
        n_samples=int(values.size),
        gradient=plane_gradient,
        origin=origin,
    )
