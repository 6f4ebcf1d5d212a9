"""Twist angles of parent → child → grandchild chains, over whole takes.

Conventions
-----------
* A chain's twist axis ``a`` is the unit direction from the parent joint to the child joint in
  the parent's frame: the child's OFFSET (summed over any intermediate helper joints). This works
  for world-aligned T-pose rigs (CMU), local +Y bones (Character Creator) and local ±X bones
  (Bandai) alike.
* When helper joints sit between the role parent and the role child, the child's rotation
  relative to the parent is the product of the intermediate local rotations and the child's own
  (``m1 ⊗ … ⊗ mk ⊗ qC``); the refinement keeps the intermediates as they are.
* Two parent-twist definitions are offered. The paper's: the signed swing–twist angle θP of
  ``qP = swing ⊗ twist`` about ``a`` and its frame difference ΔθP. It is undefined where the
  swing is 180° (bone frames flipped against the rest axis), where it jumps. The alternative:
  the twist about ``a`` of the body-frame increment ``qP(t−1)⁻¹ ⊗ qP(t)``, which has no such
  singularity and equals ΔθP wherever both are defined and the increment is small.
* Two child-twist definitions likewise. The paper's azimuth of ``v = qC · b_GC`` about ``a``
  (undefined when ``v`` is near ``a``, e.g. a straight knee), and the twist about ``a`` of the
  child's parent-frame increment ``qC(t) ⊗ qC(t−1)⁻¹``.
* Every increment is in radians, wrapped to (−π, π]; frame 0 has increment 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Skeleton
from mocapqa.core.rig import Chain
from mocapqa.errors import InputError
from mocapqa.kinematics.quaternion import multiply, rotate, scalar_part, vector_part

__all__ = [
    "ChainGeometry",
    "chain_geometry",
    "child_azimuth_increments",
    "child_increment_twists",
    "child_relative_quats",
    "parent_increment_twists",
    "parent_twist_angles",
    "wrap_angle",
]

_EPS = 1e-9


@dataclass(frozen=True, slots=True)
class ChainGeometry:
    """Fixed geometry of one chain.

    Parameters
    ----------
    chain : Chain
        The rig chain (side, segment, parent, child, grandchild).
    intermediates : tuple of int
        Joints strictly between parent and child, parent-most first (usually empty).
    axis : ndarray, shape (3,)
        Unit twist axis ``a`` in the parent's frame.
    grandchild_vector : ndarray, shape (3,)
        Unit child → grandchild direction ``b_GC`` in the child's frame (the child's local +Z
        when there is no grandchild, as in the paper).
    children : tuple of int
        Every direct child of the parent (the role child's path and helper bones such as
        twist and share bones); the refinement counter-rotates all of them.
    """

    chain: Chain
    intermediates: tuple[int, ...]
    axis: FloatArray
    grandchild_vector: FloatArray
    children: tuple[int, ...] = ()


def wrap_angle(angles_rad: FloatArray) -> FloatArray:
    """Wrap angles in radians to (−π, π], same shape."""
    return np.pi - np.mod(np.pi - angles_rad, 2.0 * np.pi)


def _path_offset(skeleton: Skeleton, top: int, bottom: int) -> tuple[tuple[int, ...], FloatArray]:
    """Joints strictly between ``top`` and ``bottom`` and the rest offset from top to bottom."""
    between: list[int] = []
    offset = np.array(skeleton.offsets[bottom], dtype=np.float64)
    j = int(skeleton.parents[bottom])
    while j != top:
        if j < 0:
            raise InputError(
                f"Expected {skeleton.names[bottom]!r} below {skeleton.names[top]!r}, got no path"
            )
        between.append(j)
        offset = offset + skeleton.offsets[j]
        j = int(skeleton.parents[j])
    return tuple(reversed(between)), offset


def chain_geometry(skeleton: Skeleton, chain: Chain) -> ChainGeometry:
    """Twist axis and grandchild direction of a chain from the rest offsets.

    Parameters
    ----------
    skeleton : Skeleton
    chain : Chain

    Returns
    -------
    ChainGeometry

    Raises
    ------
    InputError
        If the parent → child offset has zero length (no twist axis).
    """
    between, offset = _path_offset(skeleton, chain.parent, chain.child)
    length = float(np.linalg.norm(offset))
    if length < _EPS:
        raise InputError(
            f"Expected a non-zero offset from {skeleton.names[chain.parent]!r} to "
            f"{skeleton.names[chain.child]!r}, got length {length}"
        )
    grand = np.array([0.0, 0.0, 1.0])
    if chain.grandchild is not None:
        _, g_offset = _path_offset(skeleton, chain.child, chain.grandchild)
        g_length = float(np.linalg.norm(g_offset))
        if g_length > _EPS:
            grand = g_offset / g_length
    children = tuple(int(j) for j in np.flatnonzero(skeleton.parents == chain.parent))
    return ChainGeometry(chain, between, offset / length, grand, children)


def child_relative_quats(quats: FloatArray, geometry: ChainGeometry) -> FloatArray:
    """The child's rotation relative to the parent, ``m1 ⊗ … ⊗ mk ⊗ qC``, shape (F, 4)."""
    out = quats[:, geometry.chain.child]
    for j in reversed(geometry.intermediates):
        out = multiply(quats[:, j], out)
    return out


def parent_twist_angles(parent_quats: FloatArray, axes: FloatArray) -> FloatArray:
    """Swing–twist angle θP of each parent rotation about its axis (paper, eq. 1–4).

    Parameters
    ----------
    parent_quats : ndarray, shape (F, C, 4)
        Local rotations of the parents of C chains.
    axes : ndarray, shape (C, 3)
        Unit twist axes.

    Returns
    -------
    ndarray, shape (F, C)
        Radians in (−π, π]; 0 where the swing is exactly 180° (see
        :func:`mocapqa.kinematics.swing_twist.twist_angle`, which this equals).
    """
    return _twist_of(parent_quats, axes)


def _twist_of(quats: FloatArray, axes: FloatArray) -> FloatArray:
    """Signed twist angle about unit ``axes`` of ``(F, C, 4)`` quaternions, either sign, (−π, π].

    ``q`` and ``−q`` give the same angle (the scalar part is made non-negative first), so
    increments need no hemisphere unwrapping.
    """
    vec = vector_part(quats)
    proj = vec[..., 0] * axes[:, 0] + vec[..., 1] * axes[:, 1] + vec[..., 2] * axes[:, 2]
    w = scalar_part(quats)
    sign = np.where(w < 0.0, -1.0, 1.0)
    return 2.0 * np.arctan2(proj * sign, w * sign)


def _increment_twists(quats: FloatArray, axes: FloatArray, body_frame: bool) -> FloatArray:
    """Twist about the axes of ``q(t−1)⁻¹ ⊗ q(t)`` (body frame) or ``q(t) ⊗ q(t−1)⁻¹``.

    Only the axis component of the increment's vector part is formed:
    ``w1 (v2·a) − w2 (v1·a) ∓ a·(v1 × v2)`` with scalar ``w1 w2 + v1·v2``.
    """
    out = np.zeros(quats.shape[:2])
    if quats.shape[0] < 2:
        return out
    # Component planes (F, C), contiguous, for fast elementwise arithmetic.
    x, y, z = np.moveaxis(vector_part(quats), -1, 0).copy()
    w = np.ascontiguousarray(scalar_part(quats))
    ax, ay, az = axes[:, 0], axes[:, 1], axes[:, 2]
    along = x * ax + y * ay + z * az
    x1, y1, z1, w1 = x[:-1], y[:-1], z[:-1], w[:-1]
    x2, y2, z2, w2 = x[1:], y[1:], z[1:], w[1:]
    triple = ax * (y1 * z2 - z1 * y2) + ay * (z1 * x2 - x1 * z2) + az * (x1 * y2 - y1 * x2)
    proj = w1 * along[1:] - w2 * along[:-1] + (-triple if body_frame else triple)
    scalar = w1 * w2 + x1 * x2 + y1 * y2 + z1 * z2
    sign = np.where(scalar < 0.0, -1.0, 1.0)
    out[1:] = 2.0 * np.arctan2(proj * sign, scalar * sign)
    return out


def parent_increment_twists(parent_quats: FloatArray, axes: FloatArray) -> FloatArray:
    """Twist of the body-frame increment ``qP(t−1)⁻¹ ⊗ qP(t)`` about the axis.

    Parameters
    ----------
    parent_quats : ndarray, shape (F, C, 4)
    axes : ndarray, shape (C, 3)

    Returns
    -------
    ndarray, shape (F, C)
        ΔθP in radians, (−π, π]; row 0 is zero.
    """
    return _increment_twists(parent_quats, axes, body_frame=True)


def child_increment_twists(child_quats: FloatArray, axes: FloatArray) -> FloatArray:
    """Twist of the child's parent-frame increment ``qC(t) ⊗ qC(t−1)⁻¹`` about the axis.

    Parameters
    ----------
    child_quats : ndarray, shape (F, C, 4)
        Child rotations relative to the chain parents.
    axes : ndarray, shape (C, 3)
        Unit twist axes in the parents' frames.

    Returns
    -------
    ndarray, shape (F, C)
        ΔθC in radians, (−π, π]; row 0 is zero.
    """
    return _increment_twists(child_quats, axes, body_frame=False)


def child_azimuth_increments(
    child_quats: FloatArray, axes: FloatArray, grandchild_vectors: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Azimuth increments of ``v = qC · b_GC`` about the axis (paper, eq. 5–7).

    Parameters
    ----------
    child_quats : ndarray, shape (F, C, 4)
    axes : ndarray, shape (C, 3)
    grandchild_vectors : ndarray, shape (C, 3)
        Unit ``b_GC`` in the child frames.

    Returns
    -------
    increments : ndarray, shape (F, C)
        ΔθC in radians, (−π, π]; row 0 is zero.
    conditioning : ndarray, shape (F, C)
        ``|v⊥|`` per frame (the sine of the angle between ``v`` and ``a``); the azimuth is
        ill-conditioned where it is small.
    """
    v = rotate(child_quats, np.broadcast_to(grandchild_vectors, (*child_quats.shape[:2], 3)))
    a = axes[None]
    perp = v - np.sum(v * a, axis=-1, keepdims=True) * a
    conditioning = np.linalg.norm(perp, axis=-1)
    out = np.zeros(conditioning.shape)
    if v.shape[0] > 1:
        cross = np.sum(np.cross(perp[:-1], perp[1:]) * a, axis=-1)
        dot = np.sum(perp[:-1] * perp[1:], axis=-1)
        out[1:] = np.arctan2(cross, dot)
    return out, conditioning
