"""Vectorised unit-quaternion operations.

Conventions
-----------
Scalar-last ``(x, y, z, w)`` (scipy's default), Hamilton product, active rotations. This is the
only module that indexes the scalar part ``[..., 3]`` directly. ``pybvh`` and ``pytransform3d``
use ``(w, x, y, z)``; that order appears only in :func:`quats_xyzw_from_wxyz` and its inverse.
Sequences are made hemisphere-continuous with :func:`unwrap` before differencing or filtering;
the canonical ``w >= 0`` form (:func:`canonical`) is for display only.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray

__all__ = [
    "IDENTITY",
    "axis_angle_from_quats",
    "canonical",
    "conjugate",
    "exp_map",
    "geodesic_angle",
    "log_map",
    "multiply",
    "normalize",
    "quats_from_axis_angle",
    "quats_wxyz_from_xyzw",
    "quats_xyzw_from_wxyz",
    "rotate",
    "scalar_part",
    "unwrap",
    "vector_part",
]

IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])
"""The identity rotation, scalar-last ``(0, 0, 0, 1)``."""


def scalar_part(quats: FloatArray) -> FloatArray:
    """The scalar ``w`` of quaternions ``(..., 4)``, shape ``(...)``."""
    return quats[..., 3]


def vector_part(quats: FloatArray) -> FloatArray:
    """The vector ``(x, y, z)`` of quaternions ``(..., 4)``, shape ``(..., 3)``."""
    return quats[..., :3]


def multiply(p: FloatArray, q: FloatArray) -> FloatArray:
    """Hamilton product ``p ⊗ q`` with broadcasting.

    Parameters
    ----------
    p, q : ndarray, shape (..., 4)
        Quaternions, scalar-last.

    Returns
    -------
    ndarray, shape (..., 4)
    """
    px, py, pz, pw = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qx, qy, qz, qw = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        (
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz,
        ),
        axis=-1,
    )


def conjugate(quats: FloatArray) -> FloatArray:
    """Conjugate (the inverse, for unit quaternions), shape as input."""
    out = quats.copy()
    out[..., :3] *= -1.0
    return out


def normalize(quats: FloatArray) -> FloatArray:
    """Scale quaternions ``(..., 4)`` to unit norm."""
    unit: FloatArray = quats / np.linalg.norm(quats, axis=-1, keepdims=True)
    return unit


def rotate(quats: FloatArray, vectors: FloatArray) -> FloatArray:
    """Rotate ``vectors (..., 3)`` by unit ``quats (..., 4)`` (broadcast), shape ``(..., 3)``."""
    # v + w·t + u × t with t = 2 u × v, written per component: np.cross spends most of its
    # time moving axes (5× slower on (F, J, 3) batches).
    x, y, z, w = quats[..., 0], quats[..., 1], quats[..., 2], quats[..., 3]
    vx, vy, vz = vectors[..., 0], vectors[..., 1], vectors[..., 2]
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return np.stack(
        (
            vx + w * tx + (y * tz - z * ty),
            vy + w * ty + (z * tx - x * tz),
            vz + w * tz + (x * ty - y * tx),
        ),
        axis=-1,
    )


def quats_from_axis_angle(axes: FloatArray, angles_rad: FloatArray | float) -> FloatArray:
    """Quaternions rotating by ``angles_rad`` about unit ``axes (..., 3)`` (broadcast)."""
    half = 0.5 * np.asarray(angles_rad, dtype=np.float64)[..., None]
    axes = np.asarray(axes, dtype=np.float64)
    vec = axes * np.sin(half)
    w = np.broadcast_to(np.cos(half), (*vec.shape[:-1], 1))
    return np.concatenate((vec, w), axis=-1)


def exp_map(rotvecs: FloatArray) -> FloatArray:
    """Unit quaternions from rotation vectors ``(..., 3)`` (axis × angle, radians)."""
    angle = np.linalg.norm(rotvecs, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(x/2)/x → 1/2 as x → 0; the series keeps full precision for tiny angles.
    small = angle < 1e-8
    safe = np.where(small, 1.0, angle)
    scale = np.where(small, 0.5 - angle**2 / 48.0, np.sin(half) / safe)
    return np.concatenate((rotvecs * scale, np.cos(half)), axis=-1)


def log_map(quats: FloatArray) -> FloatArray:
    """Rotation vectors ``(..., 3)`` of unit quaternions (angle in [0, 2π) by the given sign).

    The result follows the quaternion's hemisphere: ``q`` and ``-q`` give vectors of angle θ and
    2π − θ about opposite axes. Call :func:`canonical` first for the shortest vector.
    """
    vec = quats[..., :3]
    sin_half = np.linalg.norm(vec, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(sin_half, quats[..., 3:4])
    small = sin_half < 1e-12
    # angle / sin(angle/2) → 2 / w as the vector part vanishes (w = ±1 there).
    w = quats[..., 3:4]
    scale = np.where(
        small, 2.0 / np.where(w == 0.0, 1.0, w), angle / np.where(small, 1.0, sin_half)
    )
    return vec * scale


def axis_angle_from_quats(quats: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Unit axes ``(..., 3)`` and angles ``(...)`` in [0, π] of unit quaternions."""
    rotvec = log_map(canonical(quats))
    angle = np.linalg.norm(rotvec, axis=-1)
    axis = np.where(angle[..., None] > 1e-12, rotvec / np.maximum(angle, 1e-300)[..., None], 0.0)
    axis[..., 0] = np.where(angle > 1e-12, axis[..., 0], 1.0)
    return axis, angle


def canonical(quats: FloatArray) -> FloatArray:
    """The representative with ``w >= 0`` (for display and comparisons, not for filtering)."""
    return np.where(quats[..., 3:4] < 0.0, -quats, quats)


def unwrap(quats: FloatArray, axis: int = 0) -> FloatArray:
    """Flip signs so consecutive quaternions along ``axis`` lie in one hemisphere.

    The rotations are unchanged; only the double-cover sign is chosen so that
    ``dot(q[t], q[t-1]) >= 0``, which makes differences and filters meaningful.

    Parameters
    ----------
    quats : ndarray, shape (F, ..., 4)
        Quaternion sequence, time along ``axis``.
    axis : int, default 0
        The time axis.
    """
    q = np.moveaxis(quats, axis, 0)
    if q.shape[0] < 2:
        return quats.copy()
    dots = np.sum(q[1:] * q[:-1], axis=-1)
    flips = np.concatenate((np.zeros((1, *dots.shape[1:]), dtype=bool), dots < 0.0), axis=0)
    sign = np.where(np.cumsum(flips, axis=0) % 2 == 1, -1.0, 1.0)
    return np.moveaxis(q * sign[..., None], 0, axis)


def geodesic_angle(p: FloatArray, q: FloatArray) -> FloatArray:
    """Angle in radians [0, π] of the rotation between ``p`` and ``q`` (sign-insensitive).

    Computed as ``4·atan2(‖p − q‖, ‖p + q‖)`` with ``q`` taken on ``p``'s hemisphere: the
    angle between two unit quaternions in 4-D is half the rotation angle, and the chord form
    keeps full precision for nearly equal rotations, where ``2·arccos(|p·q|)`` turns a 1e-16
    rounding into 1e-8 rad. It needs no quaternion product, which makes it about 2.4 times
    faster than ``2·atan2(|v|, |w|)`` of ``conj(p) ⊗ q`` (same values to 1e-15 rad).
    """
    near = np.copysign(1.0, np.einsum("...i,...i->...", p, q))[..., None] * q
    difference, total = p - near, p + near
    angle: FloatArray = 4.0 * np.arctan2(
        np.sqrt(np.einsum("...i,...i->...", difference, difference)),
        np.sqrt(np.einsum("...i,...i->...", total, total)),
    )
    return angle


def quats_xyzw_from_wxyz(quats: FloatArray) -> FloatArray:
    """Reorder ``(w, x, y, z)`` quaternions (pybvh, pytransform3d) to ``(x, y, z, w)``."""
    return np.roll(quats, -1, axis=-1)


def quats_wxyz_from_xyzw(quats: FloatArray) -> FloatArray:
    """Reorder ``(x, y, z, w)`` quaternions to ``(w, x, y, z)``."""
    return np.roll(quats, 1, axis=-1)
