"""Euler angles ↔ quaternions, through ``scipy.spatial.transform.Rotation``.

Conventions
-----------
BVH rotation channels are intrinsic rotations applied in channel order: channels
``Zrotation Yrotation Xrotation`` mean ``R = Rz(a) · Ry(b) · Rx(c)``, which is scipy's
``from_euler("ZYX", [a, b, c])`` (upper case = intrinsic). Angles are radians inside; names
ending in ``_deg`` carry degrees.

Writing Euler angles must not invent jumps. Every rotation has a family of Euler triples: 2π
shifts of each angle and, for Tait–Bryan orders, the second solution ``(a + π, π − b, c + π)``.
:func:`euler_from_quats` picks, per frame, the member nearest a reference (the angles the take
was read with, when given) or else nearest the previous frame, so the output is continuous.
"""

from __future__ import annotations

import warnings

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import ShapeError

__all__ = ["EULER_ORDERS", "euler_from_quats", "quats_from_euler"]

EULER_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
"""The six Tait–Bryan axis sequences BVH uses, intrinsic, in channel order."""

# q ⊗ e_axis for scalar-last q = (x, y, z, w): e_x gives (w, z, -y, -x), e_y (-z, w, x, -y),
# e_z (y, -x, w, -z); as (source columns, signs).
_RIGHT_UNIT_PRODUCT = {
    "X": ([3, 2, 1, 0], np.array([1.0, 1.0, -1.0, -1.0])),
    "Y": ([2, 3, 0, 1], np.array([-1.0, 1.0, 1.0, -1.0])),
    "Z": ([1, 0, 3, 2], np.array([1.0, -1.0, 1.0, -1.0])),
}


def _check_order(order: str) -> None:
    if order not in EULER_ORDERS:
        raise ShapeError(f"Expected a rotation order in {EULER_ORDERS}, got {order!r}")


def quats_from_euler(angles_rad: FloatArray, order: str) -> FloatArray:
    """Unit quaternions from intrinsic Euler angles.

    Parameters
    ----------
    angles_rad : ndarray, shape (..., 3)
        Angles in radians, in the order of ``order``.
    order : str
        Intrinsic axis sequence such as ``"ZYX"``.

    Returns
    -------
    ndarray, shape (..., 4)
        Scalar-last unit quaternions.
    """
    _check_order(order)
    angles = np.asarray(angles_rad, dtype=np.float64)
    half = 0.5 * angles
    cos, sin = np.cos(half), np.sin(half)
    # Intrinsic sequence: R = R_axis0(a0) · R_axis1(a1) · R_axis2(a2). Each right factor is
    # an elementary quaternion cos + sin·e_axis, and q ⊗ e_axis only permutes q's components
    # with signs, so composing costs a few array operations (~20× faster than
    # Rotation.from_euler on (F·J, 3) batches; scipy stays the reference in tests).
    result = np.zeros((*angles.shape[:-1], 4))
    result[..., "XYZ".index(order[0])] = sin[..., 0]
    result[..., 3] = cos[..., 0]
    for k in (1, 2):
        columns, signs = _RIGHT_UNIT_PRODUCT[order[k]]
        result = cos[..., k, None] * result + sin[..., k, None] * (result[..., columns] * signs)
    return result


def _wrap_near(angles: FloatArray, reference: FloatArray) -> FloatArray:
    """Shift ``angles`` by multiples of 2π to lie within π of ``reference``."""
    return angles - 2.0 * np.pi * np.round((angles - reference) / (2.0 * np.pi))


def euler_from_quats(
    quats: FloatArray, order: str, reference_rad: FloatArray | None = None
) -> FloatArray:
    """Continuous intrinsic Euler angles from a quaternion sequence.

    Parameters
    ----------
    quats : ndarray, shape (F, 4) or (F, J, 4)
        Unit quaternions, time on axis 0.
    order : str
        Intrinsic axis sequence such as ``"ZYX"`` (one order for all joints given).
    reference_rad : ndarray, shape like ``quats[..., :3]``, optional
        Preferred angles per frame (e.g. those the take was read with). Each frame takes the
        equivalent triple nearest to its reference; without one, nearest to the previous frame.

    Returns
    -------
    ndarray, shape (F, 3) or (F, J, 3)
        Radians, continuous in time unless the reference itself jumps.
    """
    # Imported here: scipy.spatial.transform costs ~0.5 s to import, and reading a take
    # (quats_from_euler) does not need it.
    from scipy.spatial.transform import Rotation

    _check_order(order)
    shape = quats.shape[:-1]
    flat = quats.reshape(-1, 4)
    with warnings.catch_warnings():
        # Gimbal lock is handled below by choosing among equivalent triples.
        warnings.simplefilter("ignore", UserWarning)
        first = Rotation.from_quat(flat).as_euler(order).reshape((*shape, 3))
    # The second Tait–Bryan solution of the same rotation.
    second = first + np.array([np.pi, 0.0, np.pi])
    second[..., 1] = np.pi - first[..., 1]
    if reference_rad is not None:
        ref = np.asarray(reference_rad, dtype=np.float64)
        a = _wrap_near(first, ref)
        b = _wrap_near(second, ref)
        pick_b = np.sum((b - ref) ** 2, axis=-1) < np.sum((a - ref) ** 2, axis=-1)
        chosen: FloatArray = np.where(pick_b[..., None], b, a)
        return chosen
    out: FloatArray = np.empty_like(first)
    if shape[0] == 0:
        return out
    prev = first[0]
    for t in range(shape[0]):
        a = _wrap_near(first[t], prev)
        b = _wrap_near(second[t], prev)
        pick_b = np.sum((b - prev) ** 2, axis=-1) < np.sum((a - prev) ** 2, axis=-1)
        prev = np.where(pick_b[..., None], b, a)
        out[t] = prev
    return out
