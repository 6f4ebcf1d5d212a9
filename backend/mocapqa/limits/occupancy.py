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
from mocapqa.limits.intervals import circular_intervals, dilate, smooth, wrap

__all__ = [
    "MIN_BIN_DEG",
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


MIN_BIN_DEG = 0.5
"""Smallest swing-plane bin, degrees: 720 × 720 bins per joint, half the paper's 1°. The map
holds N² bins per joint and its smoothing and nearest-bin transform cost more, so a bin of
10⁻⁶° (3.6 × 10⁸ bins a side) would ask for petabytes."""


@dataclass(frozen=True, slots=True)
class OccupancyParams:
    """Parameters of the lookup map.

    Parameters
    ----------
    bin_deg : float
        Side of a swing-plane bin in degrees, at least :data:`MIN_BIN_DEG` (0.5); 360 must be
        a whole multiple of it (paper: 1).
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
        if not MIN_BIN_DEG <= self.bin_deg <= 360.0:  # NaN too
            raise InputError(
                f"Expected `bin_deg` from {MIN_BIN_DEG:g} to 360 degrees, got {self.bin_deg:g}"
            )
        n = 360.0 / self.bin_deg
        if abs(n - round(n)) >= 1e-9:
            raise InputError(f"Expected `bin_deg` dividing 360, got {self.bin_deg:g}")
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
        centre = wrap(0.5 * (tau_min + tau_max))[nearest[0], nearest[1]]
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


def twist_bounds(
    occupancy: OccupancyMap,
    params: FloatArray,
    bins: tuple[IntArray, IntArray] | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Centre and half-width (radians) of the twist interval at each swing of ``params``.

    The bin's own values, or with ``occupancy.interpolate`` the bilinear interpolation between
    the four nearest bin centres (the centre interpolated circularly).

    Parameters
    ----------
    occupancy : OccupancyMap
    params : ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.
    bins : (ndarray, ndarray), optional
        :func:`swing_bins` of ``params``, when already computed.

    Returns
    -------
    centre, half : ndarray, shape (...)
    """
    centre, half = occupancy._centre, occupancy._half
    i1, i2 = swing_bins(params, occupancy.bin_deg) if bins is None else bins
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
            out_c += w * wrap(centre[a1 + d1, a2 + d2] - own)
            out_h += w * half[a1 + d1, a2 + d2]
    return own + out_c, out_h


def swing_bins(params: FloatArray, bin_deg: float) -> tuple[IntArray, IntArray]:
    """Bin indices ``(i1, i2)`` of the swing ``(s1, s2)`` of ``params (..., 3)`` (radians)."""
    width = np.deg2rad(bin_deg)
    n = round(360.0 / bin_deg)
    idx = np.floor((params[..., :2] + np.pi) / width).astype(np.intp)
    np.clip(idx, 0, n - 1, out=idx)
    return idx[..., 0], idx[..., 1]


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
    centre, half, occupied = circular_intervals(flat, params[:, 2], n)
    if settings.smooth:
        centre, half = smooth(centre, half, occupied)
    for _ in range(settings.dilation_bins):
        occupied, centre, half = dilate(occupied, centre, half)
    margin = np.deg2rad(settings.tau_margin_deg)
    half = np.minimum(half + margin, np.pi)
    lows = np.where(occupied, centre - half, np.nan)
    highs = np.where(occupied, centre + half, np.nan)
    return OccupancyMap(settings.bin_deg, occupied, lows, highs, settings.interpolate)


def evaluate(
    occupancy: OccupancyMap, params: FloatArray
) -> tuple[BoolArray, FloatArray, FloatArray, FloatArray]:
    """Validity, distances and signed excess in one pass (bins and twist bounds looked up once).

    A rotation is valid (the paper's ``isValid(s1, s2, τ)``) when its swing bin is occupied and
    ``τ`` lies inside the twist interval at its swing (:func:`twist_bounds`). Outside, the swing
    distance runs from ``(s1, s2)`` to the nearest occupied bin (0 inside one) and the twist
    distance from ``τ`` to the interval, the shorter way round the circle.

    Parameters
    ----------
    occupancy : OccupancyMap
    params : ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.

    Returns
    -------
    valid : ndarray of bool, shape (...)
    swing_deg, twist_deg : ndarray, shape (...)
        Degrees outside the valid region in swing and in twist; 0 for a valid rotation.
    excess_deg : ndarray, shape (..., 3)
        Signed distance of ``s1`` and ``s2`` beyond the nearest occupied bin and of ``τ``
        beyond the twist interval (positive: past the upper side); 0 inside.
    """
    shape = params.shape[:-1]
    flat = np.reshape(params, (-1, 3))
    i1, i2 = swing_bins(flat, occupancy.bin_deg)
    centre, half = twist_bounds(occupancy, flat, (i1, i2))
    offset = wrap(flat[:, 2] - centre)
    beyond = np.abs(offset) - half
    valid = occupancy.occupied[i1, i2] & (beyond <= 0.0)
    twist_deg = np.rad2deg(np.maximum(beyond, 0.0))
    swing_deg = np.zeros(flat.shape[0])
    excess = np.zeros(flat.shape)
    bad = np.flatnonzero(~valid)
    if bad.size:
        # Only invalid rotations can lie outside: a valid one is in an occupied bin (its own
        # nearest) and inside its twist interval.
        width = np.deg2rad(occupancy.bin_deg)
        gaps = np.zeros((bad.size, 2))
        for k in (0, 1):
            low = -np.pi + occupancy.nearest[k][i1[bad], i2[bad]] * width
            value = flat[bad, k]
            gaps[:, k] = value - np.clip(value, low, low + width)
        swing_deg[bad] = np.rad2deg(np.hypot(gaps[:, 0], gaps[:, 1]))
        excess[bad, :2] = np.rad2deg(gaps)
        excess[bad, 2] = np.sign(offset[bad]) * twist_deg[bad]
    return (
        valid.reshape(shape),
        swing_deg.reshape(shape),
        twist_deg.reshape(shape),
        excess.reshape(params.shape),
    )


def is_valid(occupancy: OccupancyMap, params: FloatArray) -> BoolArray:
    """The paper's ``isValid(s1, s2, τ)`` of ``params (..., 3)`` (radians), shape (...).

    The ``valid`` of :func:`evaluate`.
    """
    return evaluate(occupancy, params)[0]


def limit_distances(occupancy: OccupancyMap, params: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Degrees outside the valid region in swing and in twist of ``params (..., 3)`` (radians),
    each shape (...): the ``swing_deg`` and ``twist_deg`` of :func:`evaluate`."""
    _, swing_deg, twist_deg, _ = evaluate(occupancy, params)
    return swing_deg, twist_deg


def signed_excess(occupancy: OccupancyMap, params: FloatArray) -> FloatArray:
    """How far, and which way, each parameter of ``params (..., 3)`` (radians) lies outside
    the valid region, degrees, shape (..., 3): the ``excess_deg`` of :func:`evaluate`."""
    return evaluate(occupancy, params)[3]
