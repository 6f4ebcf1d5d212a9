"""The robust detector's events: each roll's steps against its natural velocity.

Conventions
-----------
* Increments are ``(F, C)`` arrays in radians, wrapped to (−π, π].
* A chain's natural velocity at a frame is the median of its neighbours' increments (3 per
  side, ``stride`` frames apart); an event is a frame where the parent's step departs from it by
  more than a threshold scaled to the chain's own noise and the child counter-rotates by the
  same amount (modulo 2π unless ``modular`` is off).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.detector_params import RobustParams

__all__ = ["RobustResiduals", "event_jumps", "robust_residuals"]

# An optimal sorting network for six values (12 compare–exchanges, depth 5).
_SORT6 = ((0, 5), (1, 3), (2, 4), (1, 2), (3, 4), (0, 3), (2, 5), (0, 1), (2, 3), (4, 5), (1, 2),
          (3, 4))  # fmt: skip


def _neighbour_median(
    increments: FloatArray, stride: int, rows: IntArray | None = None
) -> FloatArray:
    """Median of 6 increments around each frame, 1–3 strides away on each side (itself excluded).

    Edges are mirrored. Of the two middle values the upper is taken. With ``rows``, only those
    frames are computed (shape (R, C)).
    """
    n_frames = increments.shape[0]
    reach = 3 * stride
    padded = np.pad(increments, ((reach, reach), (0, 0)), mode="reflect")
    shifts = [reach + k * stride for k in (-3, -2, -1, 1, 2, 3)]
    if rows is not None:
        return np.sort(padded[rows[:, None] + np.array(shifts)[None, :]], axis=1)[:, 3]
    values = [np.ascontiguousarray(padded[k : k + n_frames]) for k in shifts]
    for i, j in _SORT6:
        low = np.minimum(values[i], values[j])
        values[j] = np.maximum(values[i], values[j])
        values[i] = low
    return values[3]


def _clean_median(
    increments: FloatArray, outliers: BoolArray, stride: int, rows: IntArray, fallback: FloatArray
) -> FloatArray:
    """Median of the non-outlier increments among 6 per side, ``stride`` apart, of ``rows``.

    Of the two middle values the upper is taken. Returns shape (R, C); ``fallback`` where every
    neighbour is an outlier.
    """
    n_frames = increments.shape[0]
    offsets = stride * np.array([k for k in range(-6, 7) if k != 0])
    index = np.clip(rows[:, None] + offsets[None, :], 0, n_frames - 1)
    values = np.where(outliers[index], np.inf, increments[index])  # (R, 2 half, C)
    values.sort(axis=1)
    count = np.sum(~outliers[index], axis=1)  # (R, C)
    upper = np.take_along_axis(values, (count // 2)[:, None, :], axis=1)[:, 0]
    result: FloatArray = np.where(count > 0, upper, fallback)
    return result


@dataclass(frozen=True, slots=True)
class RobustResiduals:
    """The rolls' steps against their natural velocities, and the events they make, each
    shape (F, C) unless noted: the state :func:`mocapqa.twist.detect.detect_robust` reads
    after its passes.

    Parameters
    ----------
    rp, rc : ndarray, shape (F, C)
        The parent's and the child's residual steps, radians.
    smaller : ndarray, shape (F, C)
        The smaller of their sizes, radians.
    mismatch : ndarray, shape (F, C)
        The size of their sum, radians.
    consistent : ndarray of bool, shape (F, C)
        Whether that mismatch is within the allowed counter-rotation.
    scale, threshold : ndarray, shape (C,)
        The noise scale and the jump threshold per chain, radians.
    events : ndarray of bool, shape (F, C)
        The event frames.
    natural_p, natural_c : ndarray, shape (F, C)
        The natural velocities, radians per frame.
    """

    rp: FloatArray
    rc: FloatArray
    smaller: FloatArray
    mismatch: FloatArray
    consistent: BoolArray
    scale: FloatArray
    threshold: FloatArray
    events: BoolArray
    natural_p: FloatArray
    natural_c: FloatArray


def robust_residuals(
    dp: FloatArray, dc: FloatArray, stride: int, params: RobustParams
) -> RobustResiduals:
    """The events of ``params.passes`` passes, each re-estimating the natural velocities with
    the previous pass's large steps left out.

    Parameters
    ----------
    dp, dc : ndarray, shape (F, C)
        The parent's and the child's twist increments, radians.
    stride : int
        Frames between the neighbours whose median is the natural velocity
        (:meth:`~mocapqa.twist.detector_params.RobustParams.neighbour_stride`).
    params : RobustParams

    Returns
    -------
    RobustResiduals
    """
    reach = 3 * stride
    floor = np.deg2rad(params.min_threshold_deg)
    natural_p = _neighbour_median(dp, stride)
    natural_c = _neighbour_median(dc, stride)
    for done in range(1, params.passes + 1):
        rp = wrap_angle(dp - natural_p)
        rc = wrap_angle(dc - natural_c)
        smaller = np.minimum(np.abs(rp), np.abs(rc))
        scale = 1.4826 * np.median(smaller, axis=0)
        threshold = np.maximum(floor, params.noise_factor * scale)  # (C,)
        mismatch = np.abs(wrap_angle(rp + rc)) if params.modular else np.abs(rp + rc)
        allowed = params.consistency * smaller
        if params.mismatch_noise > 0:
            # The counter-rotation is read through both rolls' noise: allow that much more.
            noise = 1.4826 * np.hypot(np.median(np.abs(rp), axis=0), np.median(np.abs(rc), axis=0))
            allowed = allowed + params.mismatch_noise * noise
        # A step must also stand out against the roll's own local speed: a fast natural roll
        # that reverses moves by about its speed in one frame.
        local = params.speed_factor * np.maximum(np.abs(natural_p), np.abs(natural_c))
        events = (smaller > np.maximum(threshold, local)) & (mismatch <= allowed)
        if not params.modular:
            events &= rp * rc < 0
        if done == params.passes:
            break
        # Natural velocities again, with the event frames replaced by the residual-free
        # estimate, so that clustered events do not bias each other's neighbours. Only rows
        # within reach of an event can change.
        # Every large step counts as an outlier here (not only consistent events), so that
        # the flips of a burst do not hide each other.
        outliers = np.maximum(np.abs(rp), np.abs(rc)) > threshold
        near = np.flatnonzero(
            np.convolve(outliers.any(axis=1), np.ones(2 * reach + 1), mode="same") > 0
        )
        natural_p = natural_p.copy()
        natural_c = natural_c.copy()
        natural_p[near] = _clean_median(dp, outliers, stride, near, natural_p[near])
        natural_c[near] = _clean_median(dc, outliers, stride, near, natural_c[near])
    return RobustResiduals(
        rp, rc, smaller, mismatch, mismatch <= allowed, scale, threshold, events, natural_p,
        natural_c,
    )  # fmt: skip


def event_jumps(res: RobustResiduals, params: RobustParams) -> FloatArray:
    """The jump of each event (0 elsewhere), radians, shape (F, C).

    Parameters
    ----------
    res : RobustResiduals
        The steps and events of :func:`robust_residuals`.
    params : RobustParams
        ``weighted_jumps`` chooses the inverse-variance weighted mean of the parent's step and
        the child's counter-step over their circular mean.

    Returns
    -------
    ndarray, shape (F, C)
    """
    rp, rc = res.rp, res.rc
    rows, cols = np.nonzero(res.events)
    jumps = np.zeros_like(rp)
    if params.weighted_jumps:
        # Two measurements of one jump: the parent's step and the child's counter-step, each
        # weighted by the inverse variance of its chain's residuals (a jittery parent roll
        # next to a still child is read mostly from the child).
        var_p = (1.4826 * np.median(np.abs(rp), axis=0)) ** 2 + 1e-8
        var_c = (1.4826 * np.median(np.abs(rc), axis=0)) ** 2 + 1e-8
        weight_c = (var_p / (var_p + var_c))[cols]
        gap = wrap_angle(-rc[rows, cols] - rp[rows, cols])
        jumps[rows, cols] = wrap_angle(rp[rows, cols] + weight_c * gap)
    else:
        # The circular mean of the parent's step and the child's counter-step.
        jumps[rows, cols] = np.angle(np.exp(1j * rp[rows, cols]) + np.exp(-1j * rc[rows, cols]))
    return jumps
