"""Resampling a take to another frame rate: slerp for rotations, linear for translations."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.kinematics.quaternion import (
    canonical,
    conjugate,
    exp_map,
    log_map,
    multiply,
    normalize,
)

__all__ = ["resample_motion"]


def resample_motion(motion: Motion, fps: float) -> Motion:
    """The take sampled at ``fps`` over the same time span.

    Frame ``k`` of the result is at time ``k / fps``; frames run while that time is within the
    take (``(F − 1) / motion.fps``). Rotations are interpolated along the shorter great arc
    (slerp) between the two nearest source frames, translations linearly. Euler writing hints
    are dropped (the writer makes the angles continuous itself).

    Parameters
    ----------
    motion : Motion
    fps : float
        Target frame rate, frames per second (> 0).

    Returns
    -------
    Motion

    Raises
    ------
    InputError
        For a non-positive rate or a take of fewer than 2 frames.
    """
    if not (np.isfinite(fps) and fps > 0):
        raise InputError(f"Expected a positive frame rate, got {fps}")
    if motion.n_frames < 2:
        raise InputError(f"Expected at least 2 frames to resample, got {motion.n_frames}")
    duration = (motion.n_frames - 1) / motion.fps
    times = np.arange(int(np.floor(duration * fps + 1e-9)) + 1) / fps
    position = np.minimum(times * motion.fps, motion.n_frames - 1)
    lower = np.minimum(np.floor(position).astype(int), motion.n_frames - 2)
    fraction = (position - lower)[:, None]
    q0, q1 = motion.quats[lower], motion.quats[lower + 1]
    step = canonical(multiply(conjugate(q0), q1))  # the shorter arc
    quats = normalize(multiply(q0, exp_map(log_map(step) * fraction[..., None])))
    t0, t1 = motion.translations[lower], motion.translations[lower + 1]
    translations = t0 + (t1 - t0) * fraction[..., None]
    return replace(
        motion,
        quats=np.ascontiguousarray(quats),
        translations=np.ascontiguousarray(translations),
        fps=float(fps),
        euler_hint_deg=None,
    )
