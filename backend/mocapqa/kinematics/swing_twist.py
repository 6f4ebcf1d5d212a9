"""Swing–twist decomposition about an arbitrary axis.

Conventions
-----------
``q = swing ⊗ twist``: the twist (about ``axis``, in the joint's own frame) is applied first,
then the swing, whose axis is perpendicular to ``axis``. This is the twist-refinement paper's
order (methods §1). The joint-limits paper uses ``q = twist ⊗ swing``; that form is
:func:`twist_swing`. The twist is the projection of the quaternion's vector part on the axis,
renormalised. When the swing is exactly 180° the twist is undefined (w and the projected
vector both vanish); we return the identity twist there, as pytransform3d does, whereas some
engines return a 180° twist. Signed twist angles are wrapped to (−π, π].
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.kinematics.quaternion import conjugate, multiply

__all__ = ["swing_twist", "twist_angle", "twist_swing"]

_DEGENERATE = 1e-12


def _twist(quats: FloatArray, axis: FloatArray) -> FloatArray:
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    proj = np.sum(quats[..., :3] * axis, axis=-1, keepdims=True)
    twist = np.concatenate((proj * axis * np.ones_like(quats[..., :3]), quats[..., 3:4]), axis=-1)
    norm = np.linalg.norm(twist, axis=-1, keepdims=True)
    degenerate = norm < _DEGENERATE
    identity = np.zeros_like(twist)
    identity[..., 3] = 1.0
    return np.where(degenerate, identity, twist / np.where(degenerate, 1.0, norm))


def swing_twist(quats: FloatArray, axis: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Decompose ``q = swing ⊗ twist`` with the twist about ``axis``.

    Parameters
    ----------
    quats : ndarray, shape (..., 4)
        Unit quaternions, scalar-last.
    axis : ndarray, shape (..., 3)
        Twist axis in the rotation's own (child) frame; broadcast against ``quats``.

    Returns
    -------
    swing, twist : ndarray, shape (..., 4)
        ``swing`` rotates about an axis perpendicular to ``axis``; ``twist`` about ``axis``.
    """
    twist = _twist(quats, axis)
    swing = multiply(quats, conjugate(twist))
    return swing, twist


def twist_swing(quats: FloatArray, axis: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Decompose ``q = twist ⊗ swing`` (twist applied last, about ``axis`` in the parent frame).

    Returns
    -------
    twist, swing : ndarray, shape (..., 4)
    """
    twist = _twist(quats, axis)
    swing = multiply(conjugate(twist), quats)
    return twist, swing


def twist_angle(quats: FloatArray, axis: FloatArray) -> FloatArray:
    """Signed twist angle in radians (−π, π] of ``quats`` about ``axis``.

    Parameters
    ----------
    quats : ndarray, shape (..., 4)
        Unit quaternions.
    axis : ndarray, shape (..., 3)
        Unit twist axis, broadcast against ``quats``.

    Returns
    -------
    ndarray, shape (...)
        The angle of ``twist`` in ``q = swing ⊗ twist``; 0 where the swing is 180°.
    """
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    proj = np.sum(quats[..., :3] * axis, axis=-1)
    w = quats[..., 3]
    angle = 2.0 * np.arctan2(proj, w)
    angle = np.where(np.hypot(proj, w) < _DEGENERATE, 0.0, angle)
    return np.angle(np.exp(1j * angle))
