"""Swing–twist exponential-map parameters ``(s1, s2, τ)`` of a joint rotation, and back.

Conventions
-----------
The joint-limits paper's form (methods §2): ``q = q_twist ⊗ q_swing`` — the swing is applied
first and the twist last, about the bone axis. The twist-refinement code uses the other order
(``q = swing ⊗ twist``, :func:`mocapqa.kinematics.swing_twist.swing_twist`); the two agree when
the swing is zero and differ otherwise.

The bone (twist) axis ``a`` is given per joint. A right-handed frame ``(e1, a, e2)`` plays the
paper's ``(x, y, z)``: ``e1`` is the world axis least aligned with ``a``, made perpendicular to it,
and ``e2 = e1 × a``. Then, with the quaternion's components ``(q_x, q_y, q_z, q_s)`` read in that
frame::

    c_y = q_s / √(q_s² + q_y²)      s_y = q_y / √(q_s² + q_y²)      c_zx = √(q_s² + q_y²)
    s_x = (q_s q_x − q_y q_z) / c_zx                    s_z = (q_s q_z + q_x q_y) / c_zx
    τ = 2 atan(s_y / c_y)     s1, s2 = 2 atan(√(s_x² + s_z²) / c_zx) · (s_x, s_z) / √(s_x² + s_z²)

All in radians: ``τ ∈ (−π, π]`` and ``√(s1² + s2²) ∈ [0, π]``. ``q`` and ``−q`` give the same
parameters (no double cover). When the swing is exactly 180° (``c_zx = 0``) the twist is
undefined; we return ``τ = 0`` and put the whole rotation in the swing, as
:mod:`mocapqa.kinematics.swing_twist` does.

Joint rotations are first taken relative to a per-joint reference rotation
(``conj(reference) ⊗ q``, see :func:`limit_params_from_quats`) so that a rig whose rest pose
bakes large joint orientations (Character Creator legs rest at a 180° swing) is charted near
the origin, away from the swing = 180° boundary where the chart wraps.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.kinematics.quaternion import conjugate, multiply

__all__ = [
    "expmap_from_quats",
    "limit_params_from_quats",
    "quats_from_expmap",
    "swing_twist_params",
    "twist_frames",
]

_TINY = 1e-12


def twist_frames(axes: FloatArray) -> FloatArray:
    """Right-handed frames ``(e1, a, e2)`` whose middle axis is the bone axis.

    Parameters
    ----------
    axes : ndarray, shape (..., 3)
        Bone axes (need not be unit length, must be non-zero).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rows ``e1``, ``a``, ``e2`` (unit, orthogonal, ``e1 × a = e2``).
    """
    a = np.asarray(axes, dtype=np.float64)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    helper = np.zeros_like(a)
    np.put_along_axis(helper, np.argmin(np.abs(a), axis=-1)[..., None], 1.0, axis=-1)
    e1 = helper - np.sum(helper * a, axis=-1, keepdims=True) * a
    e1 = e1 / np.linalg.norm(e1, axis=-1, keepdims=True)
    e2 = np.cross(e1, a)
    return np.stack((e1, a, e2), axis=-2)


def expmap_from_quats(quats: FloatArray, axes: FloatArray) -> FloatArray:
    """Swing–twist exponential-map parameters of rotations.

    Parameters
    ----------
    quats : ndarray, shape (..., 4)
        Unit quaternions, scalar-last.
    axes : ndarray, shape (..., 3)
        Twist (bone) axis in the rotation's frame, broadcast against ``quats``.

    Returns
    -------
    ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.
    """
    frames = twist_frames(axes)
    vec = np.einsum("...ij,...j->...i", frames, quats[..., :3])
    return swing_twist_params(vec[..., 0], vec[..., 1], vec[..., 2], quats[..., 3])


def swing_twist_params(
    qx: FloatArray, qy: FloatArray, qz: FloatArray, qs: FloatArray
) -> FloatArray:
    """``(s1, s2, τ)`` from quaternion components already read in the twist frame.

    Parameters
    ----------
    qx, qy, qz, qs : ndarray, shape (...)
        Vector components in the frame ``(e1, a, e2)`` of :func:`twist_frames`, and the scalar.

    Returns
    -------
    ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians (see the module notes).
    """
    c_zx = np.hypot(qs, qy)
    degenerate = c_zx < _TINY
    safe = np.where(degenerate, 1.0, c_zx)
    s_x = np.where(degenerate, qx, (qs * qx - qy * qz) / safe)
    s_z = np.where(degenerate, qz, (qs * qz + qx * qy) / safe)
    # atan(s_y / c_y) with the sign of the pair chosen so that c_y >= 0: τ in (−π, π].
    sign = np.where(qs < 0.0, -1.0, 1.0)
    tau = np.where(degenerate, 0.0, 2.0 * np.arctan2(sign * qy, np.abs(qs)))
    tau = np.where(tau <= -np.pi, tau + 2.0 * np.pi, tau)
    sin_swing = np.hypot(s_x, s_z)
    angle = 2.0 * np.arctan2(sin_swing, np.where(degenerate, 0.0, c_zx))
    # angle / sin → 2 / c_zx as the swing vanishes.
    small = sin_swing < _TINY
    scale = np.where(small, 2.0 / safe, angle / np.where(small, 1.0, sin_swing))
    return np.stack((s_x * scale, s_z * scale, tau), axis=-1)


def quats_from_expmap(params: FloatArray, axes: FloatArray) -> FloatArray:
    """Rotations from swing–twist exponential-map parameters (inverse of :func:`expmap_from_quats`).

    Parameters
    ----------
    params : ndarray, shape (..., 3)
        ``(s1, s2, τ)`` in radians.
    axes : ndarray, shape (..., 3)
        Twist (bone) axis, broadcast against ``params``.

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions, scalar-last, ``q = q_twist ⊗ q_swing``.
    """
    params = np.asarray(params, dtype=np.float64)
    s1, s2, tau = params[..., 0], params[..., 1], params[..., 2]
    angle = np.hypot(s1, s2)
    half = 0.5 * angle
    small = angle < 1e-8
    scale = np.where(small, 0.5 - angle**2 / 48.0, np.sin(half) / np.where(small, 1.0, angle))
    s_x, s_z, c_zx = s1 * scale, s2 * scale, np.cos(half)
    s_y, c_y = np.sin(0.5 * tau), np.cos(0.5 * tau)
    local = np.stack(
        (c_y * s_x + s_y * s_z, c_zx * s_y, c_y * s_z - s_y * s_x, c_y * c_zx), axis=-1
    )
    frames = twist_frames(axes)
    vec = np.einsum("...ji,...j->...i", frames, local[..., :3])
    return np.concatenate((vec, local[..., 3:4]), axis=-1)


def limit_params_from_quats(
    quats: FloatArray, axes: FloatArray, references: FloatArray
) -> FloatArray:
    """``(s1, s2, τ)`` of joint rotations relative to per-joint reference rotations.

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Local unit quaternions of the modelled joints.
    axes : ndarray, shape (J, 3)
        Bone axis per joint, in the joint's own frame.
    references : ndarray, shape (J, 4)
        Reference rotation per joint (a model's mean pose); identity reproduces the paper.

    Returns
    -------
    ndarray, shape (F, J, 3)
        ``(s1, s2, τ)`` in radians of ``conj(reference) ⊗ q``.
    """
    relative = multiply(conjugate(np.asarray(references, dtype=np.float64)), quats)
    return expmap_from_quats(relative, axes)
