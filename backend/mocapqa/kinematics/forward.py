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
from mocapqa.kinematics.quaternion import rotate

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
    # Copies (never views of the caller's arrays): the world values overwrite them.
    lq = np.transpose(local_quats, (2, 1, 0)).copy()
    lt = np.transpose(local_translations, (2, 1, 0)).copy()
    return _frame_major(*_world_joint_major(parents, lq, lt))


def _world_joint_major(
    parents: IntArray, lq: FloatArray, lt: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """World rotations (4, J, F) and positions (3, J, F) from joint-major local ones.

    Works in place: ``lq`` and ``lt`` are overwritten with the world values and returned.
    Parents come before children, so each level reads its parents' world values and its own
    local ones (gathered as copies before its rows are written).
    """
    n_joints = len(parents)
    depth = np.zeros(n_joints, dtype=np.intp)
    for j, p in enumerate(parents):
        if p >= 0:
            depth[j] = depth[p] + 1
    # Work joint-major per component, (4, J, F) and (3, J, F): gathering a level's parents
    # then copies contiguous rows, and the products below (the formulas of `multiply` and
    # `rotate`, term for term, so results are identical) run on contiguous (n, F) blocks
    # instead of stacking (F, n, 4) arrays at every level.
    wq, wt = lq, lt  # roots: world = local
    for level in range(1, int(depth.max(initial=0)) + 1):
        joints = np.flatnonzero(depth == level)
        par = parents[joints]
        px, py, pz, pw = wq[0, par], wq[1, par], wq[2, par], wq[3, par]
        qx, qy, qz, qw = lq[0, joints], lq[1, joints], lq[2, joints], lq[3, joints]
        wq[0, joints] = pw * qx + px * qw + py * qz - pz * qy
        wq[1, joints] = pw * qy - px * qz + py * qw + pz * qx
        wq[2, joints] = pw * qz + px * qy - py * qx + pz * qw
        wq[3, joints] = pw * qw - px * qx - py * qy - pz * qz
        vx, vy, vz = lt[0, joints], lt[1, joints], lt[2, joints]
        tx = 2.0 * (py * vz - pz * vy)
        ty = 2.0 * (pz * vx - px * vz)
        tz = 2.0 * (px * vy - py * vx)
        wt[0, joints] = wt[0, par] + (vx + pw * tx + (py * tz - pz * ty))
        wt[1, joints] = wt[1, par] + (vy + pw * ty + (pz * tx - px * tz))
        wt[2, joints] = wt[2, par] + (vz + pw * tz + (px * ty - py * tx))
    return wq, wt


def _frame_major(wq: FloatArray, wt: FloatArray) -> tuple[FloatArray, FloatArray]:
    world_quats: FloatArray = np.ascontiguousarray(np.transpose(wq, (2, 1, 0)))
    world_positions: FloatArray = np.ascontiguousarray(np.transpose(wt, (2, 1, 0)))
    return world_quats, world_positions


def forward_kinematics(motion: Motion) -> tuple[FloatArray, FloatArray]:
    """World rotations ``(F, J, 4)`` and positions ``(F, J, 3)`` of a motion, file units."""
    # Local translations are built joint-major directly: the OFFSETs, then the position
    # channels (one fresh array instead of a frame-major one and its transposed copy).
    skeleton = motion.skeleton
    lt = np.empty((3, skeleton.n_joints, motion.n_frames))
    lt[...] = skeleton.offsets.T[:, :, None]
    for joint, axis, add in motion.translation_channels():
        if add:
            lt[axis, joint] += motion.translations[:, joint, axis]
        else:
            lt[axis, joint] = motion.translations[:, joint, axis]
    lq = np.ascontiguousarray(np.transpose(motion.quats, (2, 1, 0)))
    return _frame_major(*_world_joint_major(skeleton.parents, lq, lt))


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
