"""Fills of one gap of one marker from the marker itself (cubic spline) or from donor markers.

Conventions
-----------
``positions`` is ``(F, M, 3)`` float64 in the file's unit with NaN where a marker is missing and
``visible`` its ``(F, M)`` mask. A gap is marker ``m`` over frames ``a..b`` (0-based, inclusive);
the methods treat those samples as missing whatever they hold, so cross-validation can hide a
visible stretch without copying the take. ``before`` / ``after`` say whether the samples just
outside the gap (frames ``< a`` / ``> b``) may be used: false at the take's start or end. Each
method returns the filled ``(b - a + 1, 3)`` trajectory, or None when it cannot fill the gap.

The rigid fill here and the PCA fill (:mod:`mocapqa.markers.fill_pca`) predict the gap and the
recorded frames either side, then correct the prediction by its errors there (:func:`anchor`:
the linear blend of the errors at ``a - 1`` and ``b + 1``), so a fill meets the recorded samples
either side without a jump.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray

__all__ = [
    "anchor",
    "frames_around",
    "kabsch",
    "recorded_around",
    "rigid_fill",
    "spline_fill",
]


def spline_fill(
    positions: FloatArray,
    visible: BoolArray,
    m: int,
    a: int,
    b: int,
    *,
    window: int,
    max_length: int,
    before: bool = True,
    after: bool = True,
) -> FloatArray | None:
    """Fill a gap with a cubic spline through the marker's own samples either side.

    Parameters
    ----------
    positions, visible, m, a, b, before, after
        The take and the gap, as in the module's conventions.
    window : int
        Frames either side of the gap whose visible samples the spline passes through.
    max_length : int
        Longest gap (frames) the spline may fill.

    Returns
    -------
    ndarray, shape (b - a + 1, 3), or None
        None at the take's ends, for gaps longer than ``max_length`` and when fewer than two
        samples are visible on either side within ``window``.
    """
    n = positions.shape[0]
    if not (before and after) or a == 0 or b == n - 1 or b - a + 1 > max_length:
        return None
    left = np.arange(max(0, a - window), a)
    right = np.arange(b + 1, min(n, b + 1 + window))
    left, right = left[visible[left, m]], right[visible[right, m]]
    if left.size < 2 or right.size < 2:
        return None
    t = np.concatenate((left, right))
    spline = CubicSpline(t, positions[t, m], axis=0)
    return np.asarray(spline(np.arange(a, b + 1)), dtype=np.float64)


def kabsch(reference: FloatArray, current: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Rotations and translations that carry a reference point set onto each frame's set.

    Parameters
    ----------
    reference : ndarray, shape (K, 3)
        The points in the reference pose (K >= 3, not collinear).
    current : ndarray, shape (N, K, 3)
        The same points in N frames.

    Returns
    -------
    rotation : ndarray, shape (N, 3, 3)
        Proper rotations ``R`` with ``current ≈ (reference - mean(reference)) @ R.T + t``.
    translation : ndarray, shape (N, 3)
        The centroids ``t`` of ``current`` in each frame.
    """
    ref = reference - reference.mean(axis=0)
    centroid = current.mean(axis=1)
    cur = current - centroid[:, None, :]
    h = np.einsum("ki,nkj->nij", ref, cur)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.einsum("nij,njk->nik", u, vt)))
    vt[:, 2, :] *= d[:, None]
    rotation = np.einsum("nij,njk->nik", u, vt).transpose(0, 2, 1)
    return rotation, centroid


def anchor(
    predicted: FloatArray,
    times: IntArray,
    recorded: FloatArray,
    a: int,
    b: int,
    *,
    smooth: bool,
) -> FloatArray:
    """Correct a prediction over a gap by its errors at the recorded samples either side.

    Parameters
    ----------
    predicted : ndarray, shape (N, 3)
        Prediction at ``times``: the gap ``a..b`` and recorded frames either side (NaN rows
        where it could not be made).
    times : ndarray of int, shape (N,)
        Frames of ``predicted``, increasing, containing every frame of ``a..b``.
    recorded : ndarray, shape (N, 3)
        The recorded samples at ``times`` (NaN in the gap and where missing).
    a, b : int
        First and last frame of the gap.
    smooth : bool
        Interpolate the errors with a cubic spline when two or more are known on both sides;
        otherwise (or when False) blend the errors at the nearest frame either side linearly
        (a constant with one side, nothing with none).

    Returns
    -------
    ndarray, shape (b - a + 1, 3)
        The corrected prediction over ``a..b``; it meets the recorded sample at ``a - 1`` and
        ``b + 1`` when those are in ``times``.
    """
    error = recorded - predicted
    known = np.isfinite(error).all(axis=1)
    gap = (times >= a) & (times <= b)
    t_gap = times[gap].astype(np.float64)
    out = predicted[gap].copy()
    left, right = known & (times < a), known & (times > b)
    if smooth and left.sum() >= 2 and right.sum() >= 2:
        spline = CubicSpline(times[known], error[known], axis=0)
        return np.asarray(out + spline(t_gap))
    if not (left.any() or right.any()):
        return np.asarray(out)
    i0 = int(np.flatnonzero(left)[-1]) if left.any() else int(np.flatnonzero(right)[0])
    i1 = int(np.flatnonzero(right)[0]) if right.any() else i0
    t0, t1 = float(times[i0]), float(times[i1])
    w = ((t_gap - t0) / (t1 - t0))[:, None] if t1 > t0 else np.zeros((t_gap.size, 1))
    return np.asarray(out + (1.0 - w) * error[i0] + w * error[i1])


def frames_around(
    n: int, a: int, b: int, window: int, before: bool, after: bool
) -> tuple[IntArray, bool, bool]:
    """Frames ``a - window .. b + window`` clipped to the take and to the usable sides."""
    has_before = before and a > 0
    has_after = after and b < n - 1
    lo = max(0, a - window) if has_before else a
    hi = min(n, b + 1 + window) if has_after else b + 1
    return np.arange(lo, hi, dtype=np.intp), has_before, has_after


def recorded_around(
    positions: FloatArray, visible: BoolArray, m: int, times: IntArray, a: int, b: int
) -> FloatArray:
    """Marker ``m``'s recorded samples at ``times``, NaN where it is not seen or inside the
    gap ``a..b`` (inclusive): the samples a fill may be anchored to, ``(len(times), 3)``."""
    out: FloatArray = positions[times, m].copy()
    out[~visible[times, m] | ((times >= a) & (times <= b))] = np.nan
    return out


def rigid_fill(
    positions: FloatArray,
    visible: BoolArray,
    m: int,
    a: int,
    b: int,
    donors: IntArray,
    *,
    window: int,
    smooth: bool = True,
    before: bool = True,
    after: bool = True,
) -> FloatArray | None:
    """Fill a gap from three or more donor markers that ride on the same segment.

    The target's position in the donors' local frame (Kabsch fit to the donors' pose at the
    nearest usable frame) is averaged over the frames within ``window`` either side of the gap
    where target and donors are all visible, carried through the gap by the donors' motion and
    blended to meet the boundary samples.

    Parameters
    ----------
    positions, visible, m, a, b, before, after
        The take and the gap, as in the module's conventions.
    donors : ndarray of int, shape (K,)
        Donor marker indices (K >= 3), visible over ``a - 1 .. b + 1`` where those frames are
        used.
    window : int
        Frames either side of the gap used to fit the target's local position.

    Returns
    -------
    ndarray, shape (b - a + 1, 3), or None
        None with fewer than three donors or no frame near the gap where target and donors are
        all visible.
    """
    n = positions.shape[0]
    if donors.size < 3:
        return None
    times, has_before, has_after = frames_around(n, a, b, window, before, after)
    if not (has_before or has_after):
        return None
    seen = visible[times][:, donors].all(axis=1)
    times = times[seen]
    recorded = recorded_around(positions, visible, m, times, a, b)
    fit = np.flatnonzero(np.isfinite(recorded[:, 0]))
    if fit.size == 0 or np.count_nonzero((times >= a) & (times <= b)) < b - a + 1:
        return None
    donor_xyz = positions[times][:, donors]
    reference = donor_xyz[fit[np.argmin(np.abs(times[fit] - a))]]
    rot, t = kabsch(reference, donor_xyz)
    local = np.einsum("nji,nj->ni", rot[fit], recorded[fit] - t[fit]).mean(axis=0)
    predicted = np.einsum("nij,j->ni", rot, local) + t
    return anchor(predicted, times, recorded, a, b, smooth=smooth)
