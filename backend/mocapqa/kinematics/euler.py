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

# Parity of each order as a permutation of XYZ: +1 when e_a·e_b = +e_c for the three axes
# (a, b, c) in channel order, -1 when e_a·e_b = -e_c.
_PARITY = {"XYZ": 1.0, "YZX": 1.0, "ZXY": 1.0, "XZY": -1.0, "YXZ": -1.0, "ZYX": -1.0}


def _check_order(order: str) -> None:
    if order not in EULER_ORDERS:
        raise ShapeError(f"Expected a rotation order in {EULER_ORDERS}, got {order!r}")


def quats_from_euler(angles_rad: FloatArray, order: str, degrees: bool = False) -> FloatArray:
    """Unit quaternions from intrinsic Euler angles.

    Parameters
    ----------
    angles_rad : ndarray, shape (..., 3)
        Angles in radians, in the order of ``order`` (degrees when ``degrees``).
    order : str
        Intrinsic axis sequence such as ``"ZYX"``.
    degrees : bool
        Whether the angles are in degrees (as in scipy's ``Rotation.from_euler``). The result
        equals that of ``np.deg2rad`` first, bit for bit, without the extra pass.

    Returns
    -------
    ndarray, shape (..., 4)
        Scalar-last unit quaternions.
    """
    _check_order(order)
    angles = np.asarray(angles_rad, dtype=np.float64)
    # Angle axis first and contiguous, so the sines and cosines below are computed over one
    # block and every component is a contiguous (...) array. Both come from one tangent of
    # the quarter angle, t = tan(angle / 4): sin = 2t / (1 + t²), cos = (1 − t²) / (1 + t²)
    # for the half angle. One transcendental call instead of two halves the cost (numpy's
    # float64 sin and cos are scalar libm calls without AVX-512) and the error stays within a
    # few ulp. It holds for every finite angle: tan never reaches infinity in floating point
    # (π/2 is not representable) and t² cannot overflow. Computed in place in two buffers
    # (instead of nine fresh blocks to fault in) as cos = 2 / (1 + t²) − 1 and
    # sin = t (1 + cos). π/720 is π/180 divided by 4 exactly, so degrees give deg2rad's
    # result times 0.25, bit for bit.
    factor = 0.25 * (np.pi / 180.0) if degrees else 0.25
    sin = np.multiply(factor, np.moveaxis(angles, -1, 0), order="C")
    np.tan(sin, out=sin)  # t
    cos = np.square(sin)
    cos += 1.0
    np.divide(2.0, cos, out=cos)  # 2 / (1 + t²) = 1 + cos
    sin *= cos  # t (1 + cos) = 2t / (1 + t²)
    cos -= 1.0
    # Intrinsic sequence: q = q_a(a0) ⊗ q_b(a1) ⊗ q_c(a2) with q_axis(t) = cos(t/2) +
    # sin(t/2)·e_axis. With e_a·e_b = s·e_c (s the order's parity), e_b·e_c = s·e_a and
    # e_a·e_c = -s·e_b, the product is, in closed form (first the two left factors):
    #   w = ca·cb, va = sa·cb, vb = ca·sb, vc = s·sa·sb, then the right factor c:
    #   w' = cc·w - sc·vc, va' = cc·va + s·sc·vb, vb' = cc·vb - s·sc·va, vc' = cc·vc + sc·w.
    # (~40× faster than Rotation.from_euler on (F·J, 3) batches; scipy stays the reference
    # in tests.)
    parity = _PARITY[order]
    ca, cb, cc = cos[0], cos[1], cos[2]
    sa, sb, sc = sin[0], sin[1], sin[2]
    w = cb * ca
    va = cb * sa
    vb = sb * ca
    vc = sb * sa
    if parity < 0:
        vc = -vc
        signed_sc = -sc
    else:
        signed_sc = sc
    result = np.empty((*angles.shape[:-1], 4))
    result[..., 3] = cc * w - sc * vc
    result[..., "XYZ".index(order[0])] = cc * va + signed_sc * vb
    result[..., "XYZ".index(order[1])] = cc * vb - signed_sc * va
    result[..., "XYZ".index(order[2])] = cc * vc + sc * w
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
