"""Removal of twist offsets, keeping each corrected child's global orientation.

Conventions
-----------
For a chain with parent P, an offset ``o(t)`` about the axis ``a`` is removed as
``qP' = qP ⊗ R(a, −o)``, and *every* direct child X of P (the role child or the first helper on
the way to it, twist bones, share bones) is counter-rotated, ``qX' = R(a, o) ⊗ qX``, so that
``qP' ⊗ qX' = qP ⊗ qX``: the world orientation of every joint below P is unchanged. (A child
whose offset is off the axis is carried round it, so its position can move; on the corpus rigs
the children sit on the bone or at the joint.) Only the rows of frames whose offset is non-zero
are written; every other value is copied bit for bit.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import ShapeError
from mocapqa.kinematics.quaternion import conjugate, multiply, quats_from_axis_angle
from mocapqa.twist.angles import ChainGeometry

__all__ = ["refine_quats"]


def refine_quats(
    quats: FloatArray, geometries: Sequence[ChainGeometry], offsets_rad: FloatArray
) -> FloatArray:
    """Remove per-chain twist offsets from local rotations.

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Local unit quaternions (not modified).
    geometries : sequence of ChainGeometry, length C
    offsets_rad : ndarray, shape (F, C)
        Parent twist offsets to remove, radians; 0 leaves a frame untouched.

    Returns
    -------
    ndarray, shape (F, J, 4)
        Refined local rotations.

    Raises
    ------
    ShapeError
        If ``offsets_rad`` does not match the frames and chains.
    """
    expected = (quats.shape[0], len(geometries))
    if offsets_rad.shape != expected:
        raise ShapeError(
            f"Expected `offsets_rad` to have shape {expected}, got {offsets_rad.shape}"
        )
    out = quats.copy()
    # Parent-most chains first, so a later chain starts from its already corrected parent.
    order = sorted(range(len(geometries)), key=lambda c: geometries[c].chain.parent)
    for c in order:
        rows = np.flatnonzero(offsets_rad[:, c] != 0.0)
        if len(rows) == 0:
            continue
        geometry = geometries[c]
        parent = geometry.chain.parent
        forward = quats_from_axis_angle(geometry.axis, offsets_rad[rows, c])  # R(a, o)
        out[rows, parent] = multiply(out[rows, parent], conjugate(forward))
        first = geometry.intermediates[0] if geometry.intermediates else geometry.chain.child
        for j in {first, *geometry.children}:
            out[rows, j] = multiply(forward, out[rows, j])
    return out
