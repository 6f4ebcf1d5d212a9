"""The One Euro filter (Casiez, Roussel & Vogel, CHI 2012), one filter per channel.

Conventions
-----------
Cutoffs are in Hz and ``beta`` is in Hz per (unit/s) of the data, so the same physical
behaviour needs ``beta`` divided by the units-per-metre factor when the length unit changes.
The derivative is ``(x_t − x̂_{t−1}) · fps``, low-passed at ``d_cutoff_hz``; the signal cutoff is
``min_cutoff_hz + beta · |dx̂|``; the smoothing factor is ``α = 1 / (1 + τ/Δt)`` with
``τ = 1 / (2π f_c)``. Missing samples (NaN, or confidence below ``min_confidence``) hold the
previous output and are reported as bridged; the alternative, extrapolating with the derivative,
overshoots on long gaps.

References
----------
Casiez, G., Roussel, N., Vogel, D. (2012). 1€ Filter: A Simple Speed-based Low-pass Filter for
Noisy Input in Interactive Systems. CHI '12, 2527–2530. doi:10.1145/2207676.2208639
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError
from mocapqa.filters.ranges import BELOW_ONE, FREQUENCY, NON_NEGATIVE, bounded, check_ranges
from mocapqa.filters.streaming import channel_count, run_streaming

__all__ = [
    "OneEuroFilter",
    "OneEuroParams",
    "check_cutoffs",
    "one_euro_filter",
    "smoothing_factor",
]


@dataclass(frozen=True, slots=True)
class OneEuroParams:
    """Parameters of the One Euro filter.

    Parameters
    ----------
    min_cutoff_hz : float
        Cutoff at zero speed, Hz (> 0).
    beta : float
        Cutoff slope, Hz per (unit/s) of the data (>= 0).
    d_cutoff_hz : float
        Cutoff of the derivative low-pass, Hz (> 0).
    min_confidence : float
        Samples with a confidence at or below this are treated as missing.
    """

    min_cutoff_hz: float = bounded(1.0, FREQUENCY)
    beta: float = bounded(0.007, NON_NEGATIVE)
    d_cutoff_hz: float = bounded(1.0, FREQUENCY)
    min_confidence: float = bounded(0.0, BELOW_ONE)

    def __post_init__(self) -> None:
        check_ranges(self)
        check_cutoffs(self.min_cutoff_hz, self.d_cutoff_hz, self.beta)


def check_cutoffs(min_cutoff_hz: float, d_cutoff_hz: float, beta: float) -> None:
    """Refuse One Euro settings (positional or quaternion) whose cutoffs (Hz) are not
    positive or whose slope is negative.

    Raises
    ------
    InputError
    """
    if not (min_cutoff_hz > 0 and d_cutoff_hz > 0 and beta >= 0):
        raise InputError(
            "Expected `min_cutoff_hz` > 0, `d_cutoff_hz` > 0 and `beta` >= 0, got "
            f"{min_cutoff_hz}, {d_cutoff_hz} and {beta}"
        )


def smoothing_factor(cutoff_hz: FloatArray | float, fps: float) -> FloatArray:
    """``α = 1 / (1 + τ/Δt)`` with ``τ = 1/(2π f_c)``, for cutoffs in Hz."""
    return np.asarray(1.0 / (1.0 + fps / (2.0 * math.pi * np.asarray(cutoff_hz))))


class OneEuroFilter:
    """Streaming One Euro filter over ``n_channels`` independent channels.

    Parameters
    ----------
    params : OneEuroParams
        Cutoffs and slope.
    n_channels : int
        Number of channels.
    fps : float
        Frames per second.
    """

    def __init__(self, params: OneEuroParams, n_channels: int, fps: float) -> None:
        if not fps > 0:
            raise InputError(f"Expected `fps` > 0, got {fps}")
        self.params = params
        self.fps = fps
        self._alpha_d = float(smoothing_factor(params.d_cutoff_hz, fps))
        # α(f) = 2πf / (2πf + fps): computed inline in update with two vector operations.
        self._two_pi = 2.0 * math.pi
        self._min_w = 2.0 * math.pi * params.min_cutoff_hz
        self._beta_w = 2.0 * math.pi * params.beta
        self._all_started = False
        self.value = np.full(n_channels, np.nan)
        self.derivative = np.zeros(n_channels)
        self.bridged = np.zeros(n_channels, dtype=bool)
        """Whether the last output held the previous value."""

    def update(self, values: FloatArray, confidence: FloatArray | None = None) -> FloatArray:
        """Advance one frame; ``values`` ``(N,)`` with NaN where missing; returns ``(N,)``."""
        missing = np.isnan(values)
        valid = (
            ~missing if confidence is None else (confidence > self.params.min_confidence) & ~missing
        )
        prev = self.value
        if not self._all_started:
            fresh = valid & np.isnan(prev)
            if fresh.any():
                prev = np.where(fresh, values, prev)
            self._all_started = not np.isnan(np.where(valid, values, prev)).any()
        dx = (values - prev) * self.fps
        dxh = self.derivative + self._alpha_d * (dx - self.derivative)
        cutoff = self._min_w + self._beta_w * np.abs(dxh)
        new = prev + (cutoff / (cutoff + self.fps)) * (values - prev)
        self.value = np.where(valid, new, prev)
        self.derivative = np.where(valid, dxh, self.derivative)
        self.bridged = ~valid
        return self.value.copy()


def one_euro_filter(
    values: FloatArray,
    fps: float,
    params: OneEuroParams,
    confidence: FloatArray | None = None,
) -> tuple[FloatArray, BoolArray]:
    """Filter a sequence with :class:`OneEuroFilter` (identical to streaming it).

    Parameters
    ----------
    values : ndarray, shape (F, ...)
        Samples, time on axis 0, NaN where missing.
    fps : float
        Frames per second.
    params : OneEuroParams
        Filter settings.
    confidence : ndarray, shape (F, ...), optional
        Per-sample confidence.

    Returns
    -------
    filtered : ndarray, shape (F, ...)
    bridged : ndarray of bool, shape (F, ...)
    """
    return run_streaming(OneEuroFilter(params, channel_count(values), fps), values, confidence)
