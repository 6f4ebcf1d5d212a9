"""Zero-phase Butterworth low-pass (``scipy.signal``), the offline reference filter.

Conventions
-----------
``filtfilt`` of an ``order``-th order low-pass at ``cutoff_hz`` (so the effective order is
doubled and the phase is zero). Positions: NaN gaps are filled by linear interpolation first
(and reported as bridged); leading and trailing gaps take the nearest value. Rotations: the
quaternion sequence is made hemisphere-continuous, filtered per component and renormalised; the
alternative, filtering rotation vectors, wraps at 180°. Not causal: for offline use and as the
reference in benchmarks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, check_shape
from mocapqa.errors import InputError
from mocapqa.filters.ranges import FREQUENCY, ORDER, bounded, check_ranges
from mocapqa.kinematics.quaternion import unwrap

__all__ = ["ButterworthParams", "butterworth_filter", "butterworth_quats"]


@dataclass(frozen=True, slots=True)
class ButterworthParams:
    """Parameters of the zero-phase Butterworth low-pass.

    Parameters
    ----------
    cutoff_hz : float
        Cutoff frequency, Hz (> 0 and below half the frame rate).
    order : int
        Filter order per pass (1–8).
    """

    cutoff_hz: float = bounded(6.0, FREQUENCY)
    order: int = bounded(4, ORDER)

    def __post_init__(self) -> None:
        check_ranges(self)
        if not (self.cutoff_hz > 0 and 1 <= self.order <= 8):
            raise InputError(
                f"Expected `cutoff_hz` > 0 and `order` in 1..8, got {self.cutoff_hz} and "
                f"{self.order}"
            )


def _lowpass(values: FloatArray, fps: float, params: ButterworthParams) -> FloatArray:
    nyquist = fps / 2.0
    if params.cutoff_hz >= nyquist:
        raise InputError(
            f"Expected `cutoff_hz` below the Nyquist frequency {nyquist:g} Hz, got "
            f"{params.cutoff_hz:g}"
        )
    # Imported here: scipy.signal costs about 2 CPU s to import, which every process reading
    # the filter registry (a batch client, a resume that analyses nothing) would pay.
    from scipy import signal

    b, a = signal.butter(params.order, params.cutoff_hz / nyquist)
    n = values.shape[0]
    if n < 2:
        return values.copy()
    padlen = min(3 * max(len(a), len(b)), n - 1)
    return np.asarray(signal.filtfilt(b, a, values, axis=0, padlen=padlen))


def butterworth_filter(
    values: FloatArray, fps: float, params: ButterworthParams
) -> tuple[FloatArray, BoolArray]:
    """Zero-phase low-pass of ``values`` ``(F, ...)`` along time.

    Returns
    -------
    filtered : ndarray, shape (F, ...)
        NaN only in channels with no value at all.
    bridged : ndarray of bool, shape (F, ...)
        True where the input was missing and was interpolated.
    """
    values = np.asarray(values, dtype=np.float64)
    n = values.shape[0]
    flat = values.reshape(n, -1).copy()
    missing = np.isnan(flat)
    frames = np.arange(n)
    empty = missing.all(axis=0)
    for c in np.flatnonzero(missing.any(axis=0) & ~empty):
        ok = ~missing[:, c]
        flat[~ok, c] = np.interp(frames[~ok], frames[ok], flat[ok, c])
    out = np.full_like(flat, np.nan)
    if (~empty).any():
        out[:, ~empty] = _lowpass(flat[:, ~empty], fps, params)
    return out.reshape(values.shape), missing.reshape(values.shape)


def butterworth_quats(quats: FloatArray, fps: float, params: ButterworthParams) -> FloatArray:
    """Zero-phase low-pass of ``(F, J, 4)`` rotation streams; returns unit quats ``(F, J, 4)``."""
    quats = np.asarray(quats, dtype=np.float64)
    check_shape(quats, "quats", ("F", "J", 4))
    out = _lowpass(unwrap(quats), fps, params)
    return np.asarray(out / np.linalg.norm(out, axis=-1, keepdims=True))
