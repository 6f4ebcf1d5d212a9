"""Compiled loops of forward kinematics: world rotations and positions, End Site positions.

Conventions
-----------
Forward kinematics walks the tree: a joint needs its parent's world rotation and position.
Vectorised over frames and over the joints of one tree level, NumPy spends about 1.5 µs per
array operation whatever its size, and a level takes ~85 of them (a 31-joint, 524-frame take:
~1.2 ms, most of it call overhead). These ``numba`` kernels do the same arithmetic joint by
joint in one compiled loop, term for term in the same order as
:func:`mocapqa.kinematics.quaternion.multiply` and :func:`~mocapqa.kinematics.quaternion.rotate`,
so the results are bit-identical to theirs (tests compare them).

Arrays are C-contiguous float64 and indices are checked by the callers in
:mod:`mocapqa.kinematics.forward`: the kernels do not bound-check. Joints come in file order,
parents before children.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mocapqa.core.arrays import FloatArray, IntArray

__all__ = [
    "CHANNEL",
    "OFFSET",
    "OFFSET_AND_CHANNEL",
    "end_sites_kernel",
    "place_kernel",
    "world_kernel",
]

OFFSET = 0
"""Local translation mode of one axis of a joint: its OFFSET."""
CHANNEL = 1
"""Local translation mode: the position channel's value (BVH's rule)."""
OFFSET_AND_CHANNEL = 2
"""Local translation mode: the OFFSET plus the channel (a root stored as a delta)."""


def _place(
    world_quats: FloatArray,
    world_positions: FloatArray,
    f: int,
    p: int,
    vx: float,
    vy: float,
    vz: float,
    out: FloatArray,
    i: int,
) -> None:
    """``out[f, i] = world_positions[f, p] + world_quats[f, p] · v``: a point placed by joint p.

    The terms of :func:`mocapqa.kinematics.quaternion.rotate` in its order:
    v + w·t + u × t with t = 2 u × v.
    """
    px, py, pz = world_quats[f, p, 0], world_quats[f, p, 1], world_quats[f, p, 2]
    pw = world_quats[f, p, 3]
    tx = 2.0 * (py * vz - pz * vy)
    ty = 2.0 * (pz * vx - px * vz)
    tz = 2.0 * (px * vy - py * vx)
    out[f, i, 0] = world_positions[f, p, 0] + (vx + pw * tx + (py * tz - pz * ty))
    out[f, i, 1] = world_positions[f, p, 1] + (vy + pw * ty + (pz * tx - px * tz))
    out[f, i, 2] = world_positions[f, p, 2] + (vz + pw * tz + (px * ty - py * tx))


# Compiled kernel: one joint or End Site placed by its parent (called by the two below).
place_kernel = njit(cache=True)(_place)


def _world(
    parents: IntArray,
    offsets: FloatArray,
    modes: np.ndarray,
    translations: FloatArray,
    quats: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """World rotations and positions of every joint.

    Parameters
    ----------
    parents : ndarray, shape (J,)
        Parent index per joint, -1 for a root; ``parents[j] < j``.
    offsets : ndarray, shape (J, 3)
        OFFSET of each joint.
    modes : ndarray of int8, shape (J, 3)
        Per joint and axis, the local translation: :data:`OFFSET`, :data:`CHANNEL` (from
        ``translations``) or :data:`OFFSET_AND_CHANNEL`.
    translations : ndarray, shape (F, J, 3)
        Position channel values.
    quats : ndarray, shape (F, J, 4)
        Local unit quaternions, scalar-last.

    Returns
    -------
    world_quats : ndarray, shape (F, J, 4)
    world_positions : ndarray, shape (F, J, 3)
    """
    n_frames, n_joints = quats.shape[0], quats.shape[1]
    world_quats = np.empty((n_frames, n_joints, 4))
    world_positions = np.empty((n_frames, n_joints, 3))
    local = np.empty(3)
    for f in range(n_frames):
        for j in range(n_joints):
            for axis in range(3):
                mode = modes[j, axis]
                if mode == 0:
                    local[axis] = offsets[j, axis]
                elif mode == 1:
                    local[axis] = translations[f, j, axis]
                else:
                    local[axis] = offsets[j, axis] + translations[f, j, axis]
            qx, qy, qz, qw = quats[f, j, 0], quats[f, j, 1], quats[f, j, 2], quats[f, j, 3]
            vx, vy, vz = local[0], local[1], local[2]
            p = parents[j]
            if p < 0:
                world_quats[f, j, 0] = qx
                world_quats[f, j, 1] = qy
                world_quats[f, j, 2] = qz
                world_quats[f, j, 3] = qw
                world_positions[f, j, 0] = vx
                world_positions[f, j, 1] = vy
                world_positions[f, j, 2] = vz
                continue
            px, py, pz = world_quats[f, p, 0], world_quats[f, p, 1], world_quats[f, p, 2]
            pw = world_quats[f, p, 3]
            world_quats[f, j, 0] = pw * qx + px * qw + py * qz - pz * qy
            world_quats[f, j, 1] = pw * qy - px * qz + py * qw + pz * qx
            world_quats[f, j, 2] = pw * qz + px * qy - py * qx + pz * qw
            world_quats[f, j, 3] = pw * qw - px * qx - py * qy - pz * qz
            place_kernel(world_quats, world_positions, f, p, vx, vy, vz, world_positions, j)
    return world_quats, world_positions


# Compiled kernel: world rotations and positions of every joint (see _world).
world_kernel = njit(cache=True)(_world)


def _end_sites(
    parents: IntArray,
    offsets: FloatArray,
    world_quats: FloatArray,
    world_positions: FloatArray,
) -> FloatArray:
    """World positions of End Sites ``(F, E, 3)`` from their parents' world rotations and positions.

    Parameters
    ----------
    parents : ndarray, shape (E,)
        The joint each End Site hangs from.
    offsets : ndarray, shape (E, 3)
        Each End Site's offset in its parent's frame.
    world_quats, world_positions : ndarray, shape (F, J, 4) and (F, J, 3)
        The joints' world rotations and positions.

    Returns
    -------
    ndarray, shape (F, E, 3)
    """
    out = np.empty((world_quats.shape[0], parents.shape[0], 3))
    for f in range(out.shape[0]):
        for e in range(out.shape[1]):
            vx, vy, vz = offsets[e, 0], offsets[e, 1], offsets[e, 2]
            place_kernel(world_quats, world_positions, f, parents[e], vx, vy, vz, out, e)
    return out


# Compiled kernel: world positions of the End Sites (see _end_sites).
end_sites_kernel = njit(cache=True)(_end_sites)
