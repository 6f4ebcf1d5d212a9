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
every bound. Twist bounds are not wrapped at ±180°: rotations are charted relative to a mean
pose (see :mod:`mocapqa.limits.expmap`), so the corpus' twists sit far from ±180°.

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
    "is_valid",
    "limit_distances",
    "swing_bins",
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
    """

    bin_deg: float = 1.0
    dilation_bins: int = 0
    tau_margin_deg: float = 0.0
    smooth: bool = True

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
        Twist bounds in radians (NaN where not occupied).
    """

    bin_deg: float
    occupied: BoolArray
    tau_min: FloatArray
    tau_max: FloatArray
    _nearest: IntArray = field(init=False, repr=False, compare=False)

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


def swing_bins(params: FloatArray, bin_deg: float) -> tuple[IntArray, IntArray]:
    """Bin indices ``(i1, i2)`` of the swing ``(s1, s2)`` of ``params (..., 3)`` (radians)."""
    width = np.deg2rad(bin_deg)
    n = round(360.0 / bin_deg)
    idx = np.floor((params[..., :2] + np.pi) / width).astype(np.intp)
    np.clip(idx, 0, n - 1, out=idx)
    return idx[..., 0], idx[..., 1]


def _smooth(values: FloatArray, occupied: BoolArray) -> FloatArray:
    weight = occupied.astype(np.float64)
    total = ndimage.convolve(np.where(occupied, values, 0.0), _KERNEL, mode="constant")
    norm = ndimage.convolve(weight, _KERNEL, mode="constant")
    return np.where(occupied, total / np.where(norm > 0, norm, 1.0), np.nan)


def _dilate(
    occupied: BoolArray, tau_min: FloatArray, tau_max: FloatArray
) -> tuple[BoolArray, FloatArray, FloatArray]:
    ring = ndimage.binary_dilation(occupied, structure=np.ones((3, 3), bool)) & ~occupied
    lows = ndimage.minimum_filter(np.where(occupied, tau_min, np.inf), size=3, mode="constant",
                                  cval=np.inf)  # fmt: skip
    highs = ndimage.maximum_filter(np.where(occupied, tau_max, -np.inf), size=3, mode="constant",
                                   cval=-np.inf)  # fmt: skip
    return (
        occupied | ring,
        np.where(ring, lows, tau_min),
        np.where(ring, highs, tau_max),
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
    tau_min = np.full(n * n, np.inf)
    tau_max = np.full(n * n, -np.inf)
    np.minimum.at(tau_min, flat, params[:, 2])
    np.maximum.at(tau_max, flat, params[:, 2])
    occupied = np.isfinite(tau_min).reshape(n, n)
    lows = np.where(occupied, tau_min.reshape(n, n), np.nan)
    highs = np.where(occupied, tau_max.reshape(n, n), np.nan)
    if settings.smooth:
        lows, highs = _smooth(lows, occupied), _smooth(highs, occupied)
    for _ in range(settings.dilation_bins):
        occupied, lows, highs = _dilate(occupied, lows, highs)
    margin = np.deg2rad(settings.tau_margin_deg)
    lows = np.where(occupied, np.maximum(lows - margin, -np.pi), np.nan)
    highs = np.where(occupied, np.minimum(highs + margin, np.pi), np.nan)
    return OccupancyMap(settings.bin_deg, occupied, lows, highs)


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
    tau = params[..., 2]
    with np.errstate(invalid="ignore"):
        inside = (tau >= occupancy.tau_min[i1, i2]) & (tau <= occupancy.tau_max[i1, i2])
    return np.asarray(occupancy.occupied[i1, i2] & inside)


def limit_distances(occupancy: OccupancyMap, params: FloatArray) -> tuple[FloatArray, FloatArray]:
    """How far rotations lie outside the valid region, in degrees of swing and of twist.

    The swing distance is from ``(s1, s2)`` to the nearest occupied bin (0 inside one); the twist
    distance is from ``τ`` to that bin's ``[τ_min, τ_max]``. Both are 0 for a valid rotation.

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
    tau = params[..., 2]
    twist = np.maximum(
        np.maximum(occupancy.tau_min[n1, n2] - tau, tau - occupancy.tau_max[n1, n2]), 0.0
    )
    return np.rad2deg(swing), np.rad2deg(twist)
