"""Hypothesis strategies shared by the kinematics tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

__all__ = ["angles_rad", "axes", "unit_quats"]

_finite = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)


def _normalised(min_norm: float, size: int) -> st.SearchStrategy[np.ndarray]:
    return (
        arrays(np.float64, (size,), elements=_finite)
        .filter(lambda v: float(np.linalg.norm(v)) > min_norm)
        .map(lambda v: v / np.linalg.norm(v))
    )


def unit_quats() -> st.SearchStrategy[np.ndarray]:
    """Unit quaternions ``(4,)``, scalar-last, both hemispheres."""
    return _normalised(1e-3, 4)


def axes() -> st.SearchStrategy[np.ndarray]:
    """Unit axes ``(3,)``."""
    return _normalised(1e-3, 3)


def angles_rad() -> st.SearchStrategy[np.ndarray]:
    """Euler triples ``(3,)`` in radians, up to two turns either way."""
    return arrays(np.float64, (3,), elements=st.floats(-4 * np.pi, 4 * np.pi, allow_nan=False))
