"""Canonical rotations and ``(s1, s2, τ)`` of a take's role joints: the check's hot path.

:mod:`mocapqa.limits.canonical` finds the constant frames ``C_j``; this module applies them to
every frame of a take: ``Q_j = conj(R_parent C_parent) ⊗ R_j C_j`` with ``R`` the world
rotations, then the swing–twist parameters about the canonical long axis.

Quaternions are held **component-major** here, ``(4, ...)`` with ``x, y, z, w`` first, so that
every Hamilton product runs on contiguous arrays (the scalar-last ``(..., 4)`` layout of
:mod:`mocapqa.kinematics.quaternion` reads each component with a stride of four and stacks a
new interleaved array per product). World rotations are built one level of the hierarchy at a
time, over every needed joint of that level at once, walking only the ancestors of the role
joints. The arithmetic is that of :func:`mocapqa.kinematics.quaternion.multiply`.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Motion
from mocapqa.core.rig import RigMap
from mocapqa.limits.canonical import CanonicalFrames, take_frames, without_stand_ins
from mocapqa.limits.expmap import swing_twist_params, twist_frames

__all__ = [
    "canonical_components",
    "canonical_params",
    "canonical_quats",
    "canonical_rotations",
    "product",
]


def product(p: FloatArray, q: FloatArray) -> FloatArray:
    """Hamilton product ``p ⊗ q`` of component-major quaternions ``(4, ...)`` (broadcast)."""
    px, py, pz, pw = p
    qx, qy, qz, qw = q
    return np.stack(
        (
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz,
        )
    )


def _world_components(motion: Motion, joints: np.ndarray) -> FloatArray:
    """World rotations of ``joints``, component-major and joint-major ``(4, len(joints), F)``."""
    parents = motion.skeleton.parents
    needed: set[int] = set()
    for joint in joints.tolist():
        while joint >= 0 and joint not in needed:
            needed.add(joint)
            joint = int(parents[joint])
    order = sorted(needed)
    position = {j: k for k, j in enumerate(order)}
    depth: dict[int, int] = {}
    for joint in order:  # parents come before their children in a skeleton
        parent = int(parents[joint])
        depth[joint] = 0 if parent < 0 else depth[parent] + 1
    # (4, J, F): each joint's components are contiguous runs over the frames.
    world = np.ascontiguousarray(np.transpose(motion.quats[:, order], (2, 1, 0)))
    for level in range(1, max(depth.values()) + 1):
        members = [j for j in order if depth[j] == level]
        cols = np.array([position[j] for j in members], dtype=np.intp)
        above = np.array([position[int(parents[j])] for j in members], dtype=np.intp)
        world[:, cols] = product(world[:, above], world[:, cols])
    return world[:, [position[j] for j in joints.tolist()]]


def canonical_components(motion: Motion, frames: CanonicalFrames) -> FloatArray:
    """Canonical local rotations ``Q_j = conj(R_parent C_parent) ⊗ R_j C_j``, component-major.

    Parameters
    ----------
    motion : Motion
    frames : CanonicalFrames
        From :func:`mocapqa.limits.canonical.canonical_frames` on the same skeleton.

    Returns
    -------
    ndarray, shape (4, R, F)
        Unit quaternions, ``x, y, z, w`` first, one row per role of ``frames``.
    """
    world = _world_components(motion, np.concatenate((frames.joints, frames.parents)))
    n = len(frames.joints)
    child = product(world[:, :n], np.asarray(frames.frames, dtype=np.float64).T[:, :, None])
    parent = product(world[:, n:], np.asarray(frames.parent_frames, dtype=np.float64).T[:, :, None])
    parent[:3] *= -1.0
    return product(parent, child)


def canonical_rotations(motion: Motion, frames: CanonicalFrames) -> FloatArray:
    """:func:`canonical_components` as scalar-last unit quaternions, shape (F, R, 4)."""
    return np.transpose(canonical_components(motion, frames), (2, 1, 0))


def canonical_params(motion: Motion, frames: CanonicalFrames, axis: FloatArray) -> FloatArray:
    """``(s1, s2, τ)`` in radians of the canonical rotations about ``axis (3,)``, (F, R, 3).

    Equal to :func:`mocapqa.limits.expmap.expmap_from_quats` of :func:`canonical_rotations`;
    a view whose columns ``[:, r]`` are contiguous ``(F, 3)`` blocks.
    """
    quats = canonical_components(motion, frames)
    basis = twist_frames(np.asarray(axis, dtype=np.float64))
    vec = np.tensordot(basis, quats[:3], axes=1)
    return np.swapaxes(swing_twist_params(vec[0], vec[1], vec[2], quats[3]), 0, 1)


def canonical_quats(
    motion: Motion, rig: RigMap | None = None, known: CanonicalFrames | None = None
) -> tuple[CanonicalFrames, FloatArray]:
    """Canonical frames of a take (:func:`mocapqa.limits.canonical.take_frames`) and its
    canonical rotations ``(F, R, 4)``, for building a model: roles whose parent role is only
    stood in for are left out (their rotations are relative to the body, not to that role)."""
    frames = without_stand_ins(take_frames(motion, rig, known))
    return frames, canonical_rotations(motion, frames)
