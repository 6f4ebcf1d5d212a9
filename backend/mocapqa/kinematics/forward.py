"""Forward kinematics: world rotations and positions of every joint.

Conventions
-----------
``world_rot[j] = world_rot[parent] ⊗ local[j]`` and
``world_pos[j] = world_pos[parent] + world_rot[parent] · translation[j]``, where the
translation is the joint's OFFSET (or its position channels, see
:meth:`mocapqa.core.motion.Motion.local_translations`). The loop runs over tree depth (≤ ~20
levels) and is vectorised over frames and over every joint at one depth.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.core.motion import Motion
from mocapqa.kinematics.quaternion import multiply, rotate

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
    """
    n_joints = len(parents)
    depth = np.zeros(n_joints, dtype=np.intp)
    for j, p in enumerate(parents):
        if p >= 0:
            depth[j] = depth[p] + 1
    world_quats = np.empty_like(local_quats)
    world_positions = np.empty_like(local_translations)
    roots = depth == 0
    world_quats[:, roots] = local_quats[:, roots]
    world_positions[:, roots] = local_translations[:, roots]
    for level in range(1, int(depth.max(initial=0)) + 1):
        joints = np.flatnonzero(depth == level)
        par = parents[joints]
        parent_rot = world_quats[:, par]
        world_quats[:, joints] = multiply(parent_rot, local_quats[:, joints])
        world_positions[:, joints] = world_positions[:, par] + rotate(
            parent_rot, local_translations[:, joints]
        )
    return world_quats, world_positions


def forward_kinematics(motion: Motion) -> tuple[FloatArray, FloatArray]:
    """World rotations ``(F, J, 4)`` and positions ``(F, J, 3)`` of a motion, file units."""
    return world_from_local(motion.skeleton.parents, motion.quats, motion.local_translations())


def end_site_positions(
    motion: Motion, world_quats: FloatArray, world_positions: FloatArray
) -> FloatArray:
    """World positions of the End Sites, shape (F, E, 3), in ``skeleton.end_sites`` order."""
    sites = motion.skeleton.end_sites
    if not sites:
        return np.zeros((motion.n_frames, 0, 3))
    par = np.array([e.parent for e in sites], dtype=np.intp)
    offs = np.array([e.offset for e in sites], dtype=np.float64)
    return world_positions[:, par] + rotate(world_quats[:, par], offs)
