"""A twist detection's result, and the frames it covers.

Conventions
-----------
* A detection covers C chains over F frames: increments, events and offsets are ``(F, C)``
  arrays in radians.
* Bind-pose first frames (:func:`leading_pose_frames`) are left out of the detection, and
  :func:`shift_detection` puts them back as frames with no increment, event or offset.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.twist.chain_events import DetectedInterval

__all__ = ["MAX_HELD_POSE_FRAMES", "Detection", "leading_pose_frames", "runs", "shift_detection"]

MAX_HELD_POSE_FRAMES = 240
"""Most leading frames read as one held bind pose (a T-pose held longer is motion)."""


@dataclass(frozen=True, slots=True)
class Detection:
    """Detection result for C chains over F frames.

    Parameters
    ----------
    parent_increments : ndarray, shape (F, C)
        ΔθP, radians.
    child_increments : ndarray, shape (F, C)
        ΔθC, radians.
    candidates : ndarray of bool, shape (F, C)
        Candidate (paper) or event (robust) frames.
    offsets : ndarray, shape (F, C)
        offset(t), radians; exactly 0 outside intervals for the robust method.
    intervals : tuple of DetectedInterval
    jumps : ndarray, shape (F, C), optional
        The jump read at each event (robust method), radians, 0 elsewhere; None for the
        paper's method.
    """

    parent_increments: FloatArray
    child_increments: FloatArray
    candidates: BoolArray
    offsets: FloatArray
    intervals: tuple[DetectedInterval, ...]
    jumps: FloatArray | None = None


def runs(mask: BoolArray) -> list[tuple[int, int]]:
    """Inclusive ``(start, end)`` of each run of True in a 1-D mask."""
    padded = np.concatenate(([False], mask, [False])).astype(np.int8)
    edges = np.diff(padded)
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return [(int(s), int(e)) for s, e in zip(starts, ends, strict=True)]


def leading_pose_frames(quats: FloatArray) -> int:
    """How many leading frames of a take are a bind pose rather than motion.

    A bind pose is frame 0, or frame 0 held unchanged for up to :data:`MAX_HELD_POSE_FRAMES`
    frames, followed by a step that :func:`mocapqa.kinematics.bindpose.leading_bind_pose`
    recognises (far larger than any later step of the take).

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Local rotations of the take.

    Returns
    -------
    int
        The number of bind-pose frames (0 when the take starts in motion).
    """
    n_frames = quats.shape[0]
    if n_frames < 3 or quats.shape[1] == 0:
        return 0
    head = quats[: min(n_frames, MAX_HELD_POSE_FRAMES + 1)]
    # Frames equal to frame 0 (to 1e-4° per joint): |q0 · qt| = cos(angle / 2).
    closeness = np.abs(np.einsum("jc,fjc->fj", head[0], head[1:])).min(axis=1)
    moved = np.flatnonzero(closeness < np.cos(np.deg2rad(1e-4) / 2.0))
    if len(moved) == 0:
        return 0
    held = int(moved[0]) + 1
    if held > MAX_HELD_POSE_FRAMES or n_frames - held < 3:
        return 0
    return held if leading_bind_pose(quats[held - 1 :]) else 0


def shift_detection(detection: Detection, skip: int, n_frames: int) -> Detection:
    """A detection made on frames ``skip`` … F − 1 of a take, as one of all ``n_frames`` frames:
    the skipped frames have no increment, no event and no offset; intervals move by ``skip``."""
    if skip == 0:
        return detection

    def pad(values: np.ndarray) -> np.ndarray:
        return np.concatenate([np.zeros((skip, *values.shape[1:]), values.dtype), values])

    return Detection(
        pad(detection.parent_increments), pad(detection.child_increments),
        pad(detection.candidates), pad(detection.offsets),
        tuple(replace(i, start_frame=i.start_frame + skip, end_frame=i.end_frame + skip)
              for i in detection.intervals),
        None if detection.jumps is None else pad(detection.jumps),
    )  # fmt: skip
