"""A bind pose (T-pose) stored as a take's first frame.

Many exports start with the rig's bind pose: the CMU walks converted by cgspeed (a synthetic
T-pose of integer angles), Character Creator takes with the status "Imported". That frame is not
part of the motion: the step into frame 1 moves most joints at once by tens of degrees. A
recursive filter started on it drags the first second of the motion toward the T-pose (the
quaternion PD filter moved frames 1–9 of the CMU walk by 54–81°), and the twist detector would
read the step as motion. So the filters start on the first frame of the motion and leave the
bind-pose frame as it is, and the twist detector gives the step into frame 1 no increment.

The test is relative to the take's own motion, so it holds at any frame rate: the step into
frame 1 (median over the joints that move at all, so a rig's constant helper and finger joints
do not dilute it) must exceed :data:`BIND_POSE_RATIO` times the largest such step later in the
take. On the 62 takes of the shared corpus the three known bind-pose frames give ratios of 7.0,
8.1 and 22.6 and every other take at most 0.9, hence a ratio of 3 (about the geometric middle).
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray

__all__ = ["BIND_POSE_RATIO", "MIN_BIND_STEP_DEG", "leading_bind_pose"]

BIND_POSE_RATIO = 3.0
"""The step into frame 1 over the largest later step above which frame 0 is a bind pose."""

_MOVING_STEP_DEG = 1e-4
"""Largest step of a joint that counts as not moving at all, degrees."""

MIN_BIND_STEP_DEG = 1.0
"""Smallest median step into frame 1 that can be a bind pose, degrees (a still take is not)."""


def leading_bind_pose(quats: FloatArray) -> int:
    """How many leading frames of a take are a bind pose rather than motion: 0 or 1.

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Local rotations of the take.

    Returns
    -------
    int
        1 when the median step into frame 1 over the moving joints is at least
        :data:`MIN_BIND_STEP_DEG` and more than :data:`BIND_POSE_RATIO` times the largest
        median step between later frames; else 0 (also for takes under 3 frames).
    """
    if quats.shape[0] < 3 or quats.shape[1] == 0:
        return 0
    # A step's angle 2·arccos|q_t · q_t+1| falls as |dot| rises, so the median and the largest
    # step are read from |dot| and only those two become angles: one dot product per cell
    # rather than an angle (on a long take the angles cost more than the twist detection).
    closeness = np.abs(np.einsum("fjc,fjc->fj", quats[:-1], quats[1:]))  # (F − 1, J)
    moving = closeness.min(axis=0) < np.cos(np.deg2rad(_MOVING_STEP_DEG) / 2.0)
    if not moving.any():
        return 0
    median = np.median(closeness[:, moving], axis=1)
    first, later = np.rad2deg(2.0 * np.arccos(np.clip([median[0], median[1:].min()], 0.0, 1.0)))
    return int(first >= MIN_BIND_STEP_DEG and first > BIND_POSE_RATIO * later)
