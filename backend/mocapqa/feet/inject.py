"""Synthetic foot errors for benchmarks and tests: slides and penetrations of a planted foot.

Conventions
-----------
* Positions are ``(F, P, 3)`` in take units and are never modified in place: each function
  returns a new array.
* A slide moves the points of one foot horizontally by ``displacement`` (take units, along the
  two horizontal axes), ramping linearly from zero at ``start`` to the full displacement at
  ``end`` and holding it afterwards, as when the root drifts while the foot is planted and the
  foot stays where it was left.
* A penetration lowers the points of one foot by ``depth`` along the up direction on
  ``start..end`` (inclusive): a foot sunk into the floor for that stretch.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.tracks import horizontal_axes

__all__ = ["inject_penetration", "inject_slide", "leg_slide_offsets"]


def _check_frames(n_frames: int, start: int, end: int) -> None:
    if not 0 <= start <= end < n_frames:
        raise InputError(f"Expected 0 ≤ start ≤ end < {n_frames}, got {start} and {end}")


def inject_slide(
    positions: FloatArray,
    points: list[int],
    start: int,
    end: int,
    displacement: tuple[float, float],
    up: UpAxis,
) -> FloatArray:
    """A copy of ``positions`` with one foot sliding horizontally over ``start..end``.

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
    points : list of int
        The points of the foot.
    start, end : int
        First and last frame of the slide, inclusive.
    displacement : tuple of float
        Total slide along the two horizontal axes (in increasing axis order), take units.
    up : UpAxis

    Returns
    -------
    ndarray, shape (F, P, 3)
    """
    _check_frames(positions.shape[0], start, end)
    out = np.array(positions, dtype=np.float64, copy=True)
    frames = np.arange(out.shape[0])
    ramp = np.clip((frames - start) / max(end - start, 1), 0.0, 1.0)
    for axis, amount in zip(horizontal_axes(up.axis), displacement, strict=True):
        out[:, points, axis] += (ramp * amount)[:, None]
    return out


def inject_penetration(
    positions: FloatArray, points: list[int], start: int, end: int, depth: float, up: UpAxis
) -> FloatArray:
    """A copy of ``positions`` with one foot lowered by ``depth`` (take units) on
    ``start..end`` (inclusive)."""
    _check_frames(positions.shape[0], start, end)
    out = np.array(positions, dtype=np.float64, copy=True)
    out[start : end + 1, points, up.axis] -= up.sign * depth
    return out


def leg_slide_offsets(
    n_frames: int,
    foot: int,
    start: int,
    end: int,
    release: int,
    displacement: FloatArray,
    blend: int,
) -> tuple[FloatArray, BoolArray]:
    """Ankle offsets of a slide injected into a motion through its leg (for the foot lock's
    bench and tests): ramping linearly from zero at ``start`` to ``displacement`` at ``end``,
    held until ``release`` (the contact's last frame), then eased back to zero over ``blend``
    frames with a smoothstep, so the take is as it was outside ``start..release + blend``.

    Parameters
    ----------
    n_frames : int
    foot : int
        0 for the left foot, 1 for the right.
    start, end, release : int
        Frames, ``start ≤ end ≤ release``.
    displacement : ndarray, shape (3,)
        Take units.
    blend : int
        Frames (≥ 1).

    Returns
    -------
    offsets : ndarray, shape (F, 2, 3)
    changed : ndarray of bool, shape (F, 2)
        The frames to solve.
    """
    _check_frames(n_frames, start, end)
    frames = np.arange(n_frames)
    ramp = np.clip((frames - start) / max(end - start, 1), 0.0, 1.0)
    x = np.clip(1.0 - (frames - release) / (blend + 1.0), 0.0, 1.0)
    ease = np.where(frames <= release, 1.0, x * x * (3.0 - 2.0 * x))
    weight = ramp * ease
    offsets = np.zeros((n_frames, 2, 3))
    offsets[:, foot] = weight[:, None] * np.asarray(displacement, dtype=np.float64)
    changed = np.zeros((n_frames, 2), dtype=bool)
    changed[:, foot] = weight > 0
    return offsets, changed
