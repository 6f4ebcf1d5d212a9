"""Forward kinematics: world rotations and positions of every joint.

Conventions
-----------
``world_rot[j] = world_rot[parent] ⊗ local[j]`` and
``world_pos[j] = world_pos[parent] + world_rot[parent] · translation[j]``, where the
translation is the joint's OFFSET (or its position channels, see
:meth:`mocapqa.core.motion.Motion.local_translations`). The walk down the tree runs in compiled
loops (:mod:`mocapqa.kinematics.kernels`, imported on first use: numba takes ~0.6 s to load);
the functions here check what the loops rely on.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.core.motion import Motion
from mocapqa.errors import ShapeError

__all__ = ["end_site_positions", "forward_kinematics", "world_from_local"]


def world_from_local(
    parents: IntArray, local_quats: FloatArray, local_translations: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """World rotations and positions from local ones.

    Parameters
    ----------
    parents : ndarray, shape (J,)
        Parent index per joint (-1 for roots), parents before children.
    local_quats : ndarray, shape (F, J, 4)
        Local unit quaternions.
    local_translations : ndarray, shape (F, J, 3)
        Translation of each joint from its parent, in the parent's frame.

    Returns
    -------
    world_quats : ndarray, shape (F, J, 4)
    world_positions : ndarray, shape (F, J, 3)

    Raises
    ------
    ShapeError
        When the shapes disagree or a parent does not come before its child.
    """
    from mocapqa.kinematics.kernels import CHANNEL, world_kernel

    parents = _checked_parents(parents)
    quats = np.ascontiguousarray(local_quats, dtype=np.float64)
    translations = np.ascontiguousarray(local_translations, dtype=np.float64)
    n_joints = len(parents)
    if quats.ndim != 3 or quats.shape[1:] != (n_joints, 4):
        raise ShapeError(f"Expected local_quats of shape (F, {n_joints}, 4), got {quats.shape}")
    if translations.shape != (*quats.shape[:2], 3):
        raise ShapeError(
            f"Expected local_translations of shape {(*quats.shape[:2], 3)}, "
            f"got {translations.shape}"
        )
    modes = np.full((n_joints, 3), CHANNEL, dtype=np.int8)
    world: tuple[FloatArray, FloatArray] = world_kernel(
        parents, np.zeros((n_joints, 3)), modes, translations, quats
    )
    return world


def _checked_parents(parents: IntArray) -> IntArray:
    """Parents as intp, each -1 or an earlier joint (the compiled loops rely on it)."""
    checked = np.ascontiguousarray(parents, dtype=np.intp)
    if checked.ndim != 1:
        raise ShapeError(f"Expected parents of shape (J,), got {checked.shape}")
    if np.any(checked < -1) or np.any(checked >= np.arange(len(checked))):
        raise ShapeError("Expected every parent to be -1 or to precede its child")
    return checked


def forward_kinematics(motion: Motion) -> tuple[FloatArray, FloatArray]:
    """World rotations ``(F, J, 4)`` and positions ``(F, J, 3)`` of a motion, file units."""
    from mocapqa.kinematics.kernels import CHANNEL, OFFSET, OFFSET_AND_CHANNEL, world_kernel

    # A Motion's arrays are validated, C-contiguous float64 of the skeleton's shapes.
    skeleton = motion.skeleton
    modes = np.full((skeleton.n_joints, 3), OFFSET, dtype=np.int8)
    for joint, axis, add in motion.translation_channels():
        modes[joint, axis] = OFFSET_AND_CHANNEL if add else CHANNEL
    world: tuple[FloatArray, FloatArray] = world_kernel(
        _checked_parents(skeleton.parents),
        np.ascontiguousarray(skeleton.offsets, dtype=np.float64),
        modes,
        np.ascontiguousarray(motion.translations, dtype=np.float64),
        np.ascontiguousarray(motion.quats, dtype=np.float64),
    )
    return world


def end_site_positions(
    motion: Motion, world_quats: FloatArray, world_positions: FloatArray
) -> FloatArray:
    """World positions of the End Sites, shape (F, E, 3), in ``skeleton.end_sites`` order."""
    from mocapqa.kinematics.kernels import end_sites_kernel

    sites = motion.skeleton.end_sites
    quats = np.ascontiguousarray(world_quats, dtype=np.float64)
    positions = np.ascontiguousarray(world_positions, dtype=np.float64)
    n_frames, n_joints = motion.n_frames, motion.skeleton.n_joints
    if quats.shape != (n_frames, n_joints, 4) or positions.shape != (n_frames, n_joints, 3):
        raise ShapeError(
            f"Expected world rotations and positions of shapes {(n_frames, n_joints, 4)} and "
            f"{(n_frames, n_joints, 3)}, got {quats.shape} and {positions.shape}"
        )
    parents = np.array([e.parent for e in sites], dtype=np.intp)
    offsets = np.array([e.offset for e in sites], dtype=np.float64).reshape(-1, 3)
    out: FloatArray = end_sites_kernel(parents, offsets, quats, positions)
    return out
