"""The lookup map of valid joint rotations: occupied swing bins and twist bounds per bin.

Conventions
-----------
The swing plane ``(s1, s2)`` over ``[−180°, 180°]²`` is cut into square bins of ``bin_deg``
(1° in the paper, methods §2). A bin is occupied when at least one corpus sample falls in it;
each occupied bin keeps ``[τ_min, τ_max]`` over its samples. Both surfaces are smoothed with a
3×3 Gaussian kernel (``[1 2 1]ᵀ[1 2 1] / 16``) taken over occupied bins only, so empty
neighbours do not pull the bounds towards zero. Two generalisation steps, off in the paper's
setting, widen a map built from few takes: ``dilation_bins`` rings of neighbouring bins become
occupied with the widest bounds of their occupied neighbours, and ``tau_margin_deg`` widens
every bound.

Twist bounds are circular intervals: a bin's interval runs from ``τ_min`` up to ``τ_max`` with
``0 ≤ τ_max − τ_min ≤ 2π``, and a twist is inside when ``wrap(τ − centre) ≤ half-width``. A bin
whose samples straddle ±180° gets the shortest arc covering them (the complement of the largest
gap between its samples), so it is never read as "everything but the arc". Smoothing and
dilation work on the interval's centre (a circular mean) and half-width. Files written before
wrapping hold intervals inside ``[−π, π]`` and read the same.

With ``interpolate`` (the default build) the twist interval is a continuous surface: centre and
half-width are interpolated bilinearly between bin centres (empty bins carry their nearest
occupied bin's values), instead of stepping at bin edges. Which swing bins are occupied is
still decided per bin.

Angles are radians inside the map; only parameter names ending in ``_deg`` hold degrees.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, as_float_array
from mocapqa.errors import InputError, ShapeError

__all__ = [
    "OccupancyMap",
    "OccupancyParams",
    "build_occupancy",
    "evaluate",
    "is_valid",
    "limit_distances",
    "signed_excess",
    "swing_bins",
    "twist_bounds",
]

_KERNEL = np.outer([1.0, 2.0, 1.0], [1.0, 2.0, 1.0]) / 16.0


@dataclass(frozen=True, slots=True)
class OccupancyParams:
    """Parameters of the lookup map.

    Parameters
    ----------
    bin_deg : float
        Side of a swing-plane bin in degrees; 360 must be a whole multiple of it (paper: 1).
    dilation_bins : int
        Rings of neighbouring bins added to the occupied set after smoothing (paper: 0).
    tau_margin_deg : float
        Degrees added on both sides of every twist interval (paper: 0).
    smooth : bool
        Apply the 3×3 Gaussian smoothing of the τ surfaces (paper: True).
    interpolate : bool
        Interpolate the twist bounds between bin centres (a continuous surface) rather than
        using each bin's own bounds (the paper's staircase; files written before it existed).
    """

    bin_deg: float = 1.0
    dilation_bins: int = 0
    tau_margin_deg: float = 0.0
    smooth: bool = True
    interpolate: bool = False

    def __post_init__(self) -> None:
        n = 360.0 / self.bin_deg if self.bin_deg > 0 else 0.0
        if not (self.bin_deg > 0 and abs(n - round(n)) < 1e-9):
            raise InputError(f"Expected `bin_deg` dividing 360, got {self.bin_deg}")
        if self.dilation_bins < 0 or self.tau_margin_deg < 0:
            raise InputError(
                "Expected `dilation_bins` >= 0 and `tau_margin_deg` >= 0, got "
                f"{self.dilation_bins} and {self.tau_margin_deg}"
            )

    @property
    def n_bins(self) -> int:
        """Bins per swing axis."""
        return round(360.0 / self.bin_deg)


@dataclass(frozen=True, slots=True)
class OccupancyMap:
    """A built lookup map for one joint.

    Parameters
    ----------
    bin_deg : float
        Bin side in degrees.
    occupied : ndarray of bool, shape (N, N)
        Occupied bins, indexed ``[s1 bin, s2 bin]`` from −180°.
    tau_min, tau_max : ndarray, shape (N, N)
        Twist bounds in radians (NaN where not occupied): the circular interval from
        ``tau_min`` up to ``tau_max``, ``0 ≤ tau_max − tau_min ≤ 2π``.
    interpolate : bool
        Twist bounds interpolated between bin centres (see the module notes).
    """

    bin_deg: float
    occupied: BoolArray
    tau_min: FloatArray
    tau_max: FloatArray
    interpolate: bool = False
    _nearest: IntArray = field(init=False, repr=False, compare=False)
    _centre: FloatArray = field(init=False, repr=False, compare=False)
    _half: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        n = round(360.0 / self.bin_deg)
        occupied = np.asarray(self.occupied, dtype=bool)
        if occupied.shape != (n, n):
            raise ShapeError(f"Expected `occupied` to have shape ({n}, {n}), got {occupied.shape}")
        tau_min = as_float_array(self.tau_min, "tau_min", (n, n), finite=False)
        tau_max = as_float_array(self.tau_max, "tau_max", (n, n), finite=False)
        if not occupied.any():
            raise InputError("Expected at least one occupied bin, got an empty map")
        if not (np.all(np.isfinite(tau_min[occupied])) and np.all(np.isfinite(tau_max[occupied]))):
            raise InputError("Expected finite twist bounds on occupied bins, got NaN")
        # Nearest occupied bin of every bin: the twist bounds used to score a swing outside.
        _, nearest = ndimage.distance_transform_edt(~occupied, return_indices=True)
        if np.any(tau_max[occupied] < tau_min[occupied] - 1e-9) or np.any(
            tau_max[occupied] - tau_min[occupied] > 2 * np.pi + 1e-6
        ):
            raise InputError("Expected 0 <= tau_max - tau_min <= 2π on occupied bins")
        # Centre and half-width of every bin, empty bins taking their nearest occupied bin's.
        centre = _wrap(0.5 * (tau_min + tau_max))[nearest[0], nearest[1]]
        half = (0.5 * (tau_max - tau_min))[nearest[0], nearest[1]]
        object.__setattr__(self, "_centre", np.ascontiguousarray(centre))
        object.__setattr__(self, "_half", np.ascontiguousarray(half))
        object.__setattr__(self, "interpolate", bool(self.interpolate))
        object.__setattr__(self, "occupied", occupied)
        object.__setattr__(self, "tau_min", tau_min)
        object.__setattr__(self, "tau_max", tau_max)
        object.__setattr__(self, "_nearest", nearest.astype(np.intp))

    @property
    def n_bins(self) -> int:
        """Bins per swing axis."""
        return int(self.occupied.shape[0])

    @property
    def nearest(self) -> IntArray:
        """Index of the nearest occupied bin per bin, shape (2, N, N)."""
        return self._nearest


def _wrap(angles: FloatArray) -> FloatArray:
    """Angles wrapped to ``[−π, π)``."""
    return np.asarray((angles + np.pi) % (2.0 * np.pi) - np.pi, dtype=np.float64)


def twist_bounds(occupancy: OccupancyMap, params: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Centre and half-width (radians) of the twist interval at each swing of ``params``.

    The bin's own values, or with ``occupancy.interpolate`` the bilinear interpolation between
    the four nearest bin centres (the centre interpolated circularly).

    Parameters
    ----------
    occupancy : OccupancyMap
    params : ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.

    Returns
    -------
    centre, half : ndarray, shape (...)
    """
    centre, half = occupancy._centre, occupancy._half
    i1, i2 = swing_bins(params, occupancy.bin_deg)
    own = centre[i1, i2]
    if not occupancy.interpolate:
        return own, half[i1, i2]
    n = occupancy.n_bins
    u = (params[..., :2] + np.pi) / np.deg2rad(occupancy.bin_deg) - 0.5
    low = np.clip(np.floor(u).astype(np.intp), 0, n - 2)
    t = np.clip(u - low, 0.0, 1.0)
    a1, a2 = low[..., 0], low[..., 1]
    t1, t2 = t[..., 0], t[..., 1]
    out_c = np.zeros_like(own)
    out_h = np.zeros_like(own)
    for d1, w1 in ((0, 1.0 - t1), (1, t1)):
        for d2, w2 in ((0, 1.0 - t2), (1, t2)):
            w = w1 * w2
            out_c += w * _wrap(centre[a1 + d1, a2 + d2] - own)
            out_h += w * half[a1 + d1, a2 + d2]
    return own + out_c, out_h


def swing_bins(params: FloatArray, bin_deg: float) -> tuple[IntArray, IntArray]:
    """Bin indices ``(i1, i2)`` of the swing ``(s1, s2)`` of ``params (..., 3)`` (radians)."""
    width = np.deg2rad(bin_deg)
    n = round(360.0 / bin_deg)
    idx = np.floor((params[..., :2] + np.pi) / width).astype(np.intp)
    np.clip(idx, 0, n - 1, out=idx)
    return idx[..., 0], idx[..., 1]


def _shifted(values: FloatArray, fill: float) -> list[tuple[float, FloatArray]]:
    """The 3×3 neighbourhood of every bin: (kernel weight, neighbour values) pairs."""
    n = values.shape[0]
    padded = np.pad(values, 1, constant_values=fill)
    return [
        (float(_KERNEL[d1 + 1, d2 + 1]), padded[1 + d1 : 1 + d1 + n, 1 + d2 : 1 + d2 + n])
        for d1 in (-1, 0, 1)
        for d2 in (-1, 0, 1)
    ]


def _smooth(
    centre: FloatArray, half: FloatArray, occupied: BoolArray
) -> tuple[FloatArray, FloatArray]:
    """3×3 Gaussian smoothing over occupied bins of the centres (the short way round from the
    bin's own) and the half-widths."""
    own = np.where(occupied, centre, 0.0)
    total_c = np.zeros_like(own)
    total_h = np.zeros_like(own)
    norm = np.zeros_like(own)
    pairs = zip(_shifted(own, 0.0), _shifted(np.where(occupied, half, 0.0), 0.0),
                _shifted(occupied.astype(np.float64), 0.0), strict=True)  # fmt: skip
    for (w, c), (_, h), (_, o) in pairs:
        total_c += w * o * _wrap(c - own)
        total_h += w * o * h
        norm += w * o
    norm = np.where(norm > 0, norm, 1.0)
    return (
        np.where(occupied, _wrap(own + total_c / norm), np.nan),
        np.where(occupied, total_h / norm, np.nan),
    )


def _dilate(
    occupied: BoolArray, centre: FloatArray, half: FloatArray
) -> tuple[BoolArray, FloatArray, FloatArray]:
    """Add one ring of bins, each with the union (widest arc) of its occupied neighbours."""
    n = occupied.shape[0]
    ring = ndimage.binary_dilation(occupied, structure=np.ones((3, 3), bool)) & ~occupied
    pad = 1
    occ = np.pad(occupied, pad)
    cen = np.pad(np.where(occupied, centre, 0.0), pad)
    hal = np.pad(np.where(occupied, half, 0.0), pad)
    sin_sum = np.zeros((n, n))
    cos_sum = np.zeros((n, n))
    shifts = [(d1, d2) for d1 in (-1, 0, 1) for d2 in (-1, 0, 1)]
    for d1, d2 in shifts:
        window = (slice(pad + d1, pad + d1 + n), slice(pad + d2, pad + d2 + n))
        sin_sum += np.where(occ[window], np.sin(cen[window]), 0.0)
        cos_sum += np.where(occ[window], np.cos(cen[window]), 0.0)
    reference = np.arctan2(sin_sum, cos_sum)
    low = np.full((n, n), np.inf)
    high = np.full((n, n), -np.inf)
    for d1, d2 in shifts:
        window = (slice(pad + d1, pad + d1 + n), slice(pad + d2, pad + d2 + n))
        mid = reference + _wrap(cen[window] - reference)
        low = np.where(occ[window], np.minimum(low, mid - hal[window]), low)
        high = np.where(occ[window], np.maximum(high, mid + hal[window]), high)
    high = np.where(ring, high, 0.0)
    low = np.where(ring, low, 0.0)
    ring_half = np.minimum(0.5 * (high - low), np.pi)
    ring_centre = _wrap(0.5 * (high + low))
    return (
        occupied | ring,
        np.where(ring, ring_centre, centre),
        np.where(ring, ring_half, half),
    )


def build_occupancy(params: FloatArray, settings: OccupancyParams) -> OccupancyMap:
    """Build the lookup map of one joint from its corpus samples.

    Parameters
    ----------
    params : ndarray, shape (N, 3)
        ``(s1, s2, τ)`` samples in radians.
    settings : OccupancyParams

    Returns
    -------
    OccupancyMap

    Raises
    ------
    ShapeError
        If ``params`` is not ``(N, 3)`` with N ≥ 1.
    """
    params = as_float_array(params, "params", ("N", 3))
    if params.shape[0] == 0:
        raise ShapeError("Expected `params` to have at least one sample, got 0")
    n = settings.n_bins
    i1, i2 = swing_bins(params, settings.bin_deg)
    flat = i1 * n + i2
    centre, half, occupied = _circular_intervals(flat, params[:, 2], n)
    if settings.smooth:
        centre, half = _smooth(centre, half, occupied)
    for _ in range(settings.dilation_bins):
        occupied, centre, half = _dilate(occupied, centre, half)
    margin = np.deg2rad(settings.tau_margin_deg)
    half = np.minimum(half + margin, np.pi)
    lows = np.where(occupied, centre - half, np.nan)
    highs = np.where(occupied, centre + half, np.nan)
    return OccupancyMap(settings.bin_deg, occupied, lows, highs, settings.interpolate)


def _circular_intervals(
    flat: IntArray, tau: FloatArray, n: int
) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Per bin, the shortest arc covering its twists: centre, half-width, occupied (N, N)."""
    centre = np.full(n * n, np.nan)
    half = np.full(n * n, np.nan)
    order = np.lexsort((tau, flat))
    flat_s, tau_s = flat[order], _wrap(tau[order])
    starts = np.flatnonzero(np.r_[True, flat_s[1:] != flat_s[:-1]])
    ends = np.r_[starts[1:], flat_s.size]
    for a, b in zip(starts, ends, strict=True):
        values = tau_s[a:b]
        gaps = np.diff(np.r_[values, values[0] + 2.0 * np.pi])
        k = int(np.argmax(gaps))
        low = values[(k + 1) % values.size]
        width = 2.0 * np.pi - gaps[k]
        centre[flat_s[a]] = _wrap(np.asarray(low + 0.5 * width))
        half[flat_s[a]] = 0.5 * width
    occupied = np.isfinite(centre).reshape(n, n)
    return centre.reshape(n, n), half.reshape(n, n), occupied


def is_valid(occupancy: OccupancyMap, params: FloatArray) -> BoolArray:
    """The paper's ``isValid(s1, s2, τ)``: swing bin occupied and τ within its bounds.

    Parameters
    ----------
    occupancy : OccupancyMap
    params : ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.

    Returns
    -------
    ndarray of bool, shape (...)
    """
    i1, i2 = swing_bins(params, occupancy.bin_deg)
    centre, half = twist_bounds(occupancy, params)
    inside = np.abs(_wrap(params[..., 2] - centre)) <= half
    return np.asarray(occupancy.occupied[i1, i2] & inside)


def limit_distances(occupancy: OccupancyMap, params: FloatArray) -> tuple[FloatArray, FloatArray]:
    """How far rotations lie outside the valid region, in degrees of swing and of twist.

    The swing distance is from ``(s1, s2)`` to the nearest occupied bin (0 inside one); the twist
    distance is from ``τ`` to the twist interval at that swing (:func:`twist_bounds`), the
    shorter way round the circle. Both are 0 for a valid rotation.

    Parameters
    ----------
    occupancy : OccupancyMap
    params : ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.

    Returns
    -------
    swing_deg, twist_deg : ndarray, shape (...)
    """
    i1, i2 = swing_bins(params, occupancy.bin_deg)
    n1 = occupancy.nearest[0][i1, i2]
    n2 = occupancy.nearest[1][i1, i2]
    width = np.deg2rad(occupancy.bin_deg)
    gaps = []
    for k, nb in ((0, n1), (1, n2)):
        low = -np.pi + nb * width
        value = params[..., k]
        gaps.append(np.maximum(np.maximum(low - value, value - (low + width)), 0.0))
    swing = np.hypot(gaps[0], gaps[1])
    centre, half = twist_bounds(occupancy, params)
    twist = np.maximum(np.abs(_wrap(params[..., 2] - centre)) - half, 0.0)
    return np.rad2deg(swing), np.rad2deg(twist)


def signed_excess(occupancy: OccupancyMap, params: FloatArray) -> FloatArray:
    """How far, and which way, each parameter lies outside the valid region, degrees.

    Parameters
    ----------
    occupancy : OccupancyMap
    params : ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.

    Returns
    -------
    ndarray, shape (..., 3)
        Signed distance of ``s1`` and ``s2`` beyond the nearest occupied bin and of ``τ``
        beyond the twist interval (positive: past the upper side); 0 inside.
    """
    i1, i2 = swing_bins(params, occupancy.bin_deg)
    width = np.deg2rad(occupancy.bin_deg)
    out = np.zeros(params.shape)
    for k in (0, 1):
        low = -np.pi + occupancy.nearest[k][i1, i2] * width
        value = params[..., k]
        out[..., k] = value - np.clip(value, low, low + width)
    centre, half = twist_bounds(occupancy, params)
    offset = _wrap(params[..., 2] - centre)
    out[..., 2] = np.sign(offset) * np.maximum(np.abs(offset) - half, 0.0)
    return np.rad2deg(out)


def evaluate(
    occupancy: OccupancyMap, params: FloatArray
) -> tuple[BoolArray, FloatArray, FloatArray, FloatArray]:
    """Validity, distances and signed excess in one pass (the twist bounds looked up once).

    Parameters
    ----------
    occupancy : OccupancyMap
    params : ndarray, shape (N, 3)
        ``(s1, s2, τ)`` in radians.

    Returns
    -------
    valid : ndarray of bool, shape (N,)
        As :func:`is_valid`.
    swing_deg, twist_deg : ndarray, shape (N,)
        As :func:`limit_distances`.
    excess_deg : ndarray, shape (N, 3)
        As :func:`signed_excess`, computed on the invalid rows only (0 elsewhere).
    """
    i1, i2 = swing_bins(params, occupancy.bin_deg)
    centre, half = twist_bounds(occupancy, params)
    offset = _wrap(params[:, 2] - centre)
    beyond = np.abs(offset) - half
    occupied = occupancy.occupied[i1, i2]
    valid = occupied & (beyond <= 0.0)
    twist_deg = np.rad2deg(np.maximum(beyond, 0.0))
    swing_deg = np.zeros(params.shape[0])
    excess = np.zeros(params.shape)
    bad = np.flatnonzero(~valid)
    if bad.size:
        width = np.deg2rad(occupancy.bin_deg)
        gaps = np.zeros((bad.size, 2))
        for k in (0, 1):
            low = -np.pi + occupancy.nearest[k][i1[bad], i2[bad]] * width
            value = params[bad, k]
            gaps[:, k] = value - np.clip(value, low, low + width)
        swing_deg[bad] = np.rad2deg(np.hypot(gaps[:, 0], gaps[:, 1]))
        excess[bad, :2] = np.rad2deg(gaps)
        excess[bad, 2] = np.rad2deg(np.sign(offset[bad]) * np.maximum(beyond[bad], 0.0))
    return valid, swing_deg, twist_deg, excess
