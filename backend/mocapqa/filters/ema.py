"""Exponential moving average with a time constant, one filter per channel.

Conventions
-----------
``x̂_t = x̂_{t−1} + α (x_t − x̂_{t−1})`` with ``α = 1 − exp(−Δt/τ)``: the time constant ``τ`` in
seconds makes 30 and 120 fps behave alike, where the note's fixed ``α = 0.3`` means a different
filter at each frame rate (``α = 0.3`` at 30 fps is ``τ ≈ 0.093 s``). Missing samples hold the
previous output and are reported as bridged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError
from mocapqa.filters.ranges import BELOW_ONE, DURATION, bounded, check_ranges
from mocapqa.filters.streaming import channel_count, run_streaming

__all__ = ["EmaFilter", "EmaParams", "ema_filter", "time_constant_from_alpha"]


@dataclass(frozen=True, slots=True)
class EmaParams:
    """Parameters of the EMA.

    Parameters
    ----------
    time_constant_s : float
        ``τ`` in seconds (> 0).
    min_confidence : float
        Samples with a confidence at or below this are treated as missing.
    """

    time_constant_s: float = bounded(0.0934, DURATION)
    min_confidence: float = bounded(0.0, BELOW_ONE)

    def __post_init__(self) -> None:
        check_ranges(self)
        if not self.time_constant_s > 0:
            raise InputError(f"Expected `time_constant_s` > 0, got {self.time_constant_s}")


def time_constant_from_alpha(alpha: float, fps: float) -> float:
    """Time constant in seconds equivalent to a per-frame ``alpha`` in (0, 1) at ``fps``."""
    if not 0 < alpha < 1:
        raise InputError(f"Expected `alpha` in (0, 1), got {alpha}")
    return -1.0 / (fps * math.log(1.0 - alpha))


class EmaFilter:
    """Streaming EMA over ``n_channels`` channels.

    Parameters
    ----------
    params : EmaParams
        Time constant.
    n_channels : int
        Number of channels.
    fps : float
        Frames per second.
    """

    def __init__(self, params: EmaParams, n_channels: int, fps: float) -> None:
        if not fps > 0:
            raise InputError(f"Expected `fps` > 0, got {fps}")
        self.params = params
        self.alpha = 1.0 - math.exp(-1.0 / (fps * params.time_constant_s))
        self.value = np.full(n_channels, np.nan)
        self.bridged = np.zeros(n_channels, dtype=bool)
        """Whether the last output held the previous value."""

    def update(self, values: FloatArray, confidence: FloatArray | None = None) -> FloatArray:
        """Advance one frame; ``values`` ``(N,)`` with NaN where missing; returns ``(N,)``."""
        valid = ~np.isnan(values)
        if confidence is not None:
            valid &= confidence > self.params.min_confidence
        prev = np.where(np.isnan(self.value), values, self.value)
        self.value = np.where(valid, prev + self.alpha * (values - prev), self.value)
        self.bridged = ~valid
        return self.value.copy()


def ema_filter(
    values: FloatArray,
    fps: float,
    params: EmaParams,
    confidence: FloatArray | None = None,
) -> tuple[FloatArray, BoolArray]:
    """Filter a sequence with :class:`EmaFilter` (identical to streaming it).

    Parameters
    ----------
    values : ndarray, shape (F, ...)
        Samples, NaN where missing.
    fps : float
        Frames per second.
    params : EmaParams
        Time constant.
    confidence : ndarray, shape (F, ...), optional
        Per-sample confidence.

    Returns
    -------
    filtered : ndarray, shape (F, ...)
    bridged : ndarray of bool, shape (F, ...)
    """
    return run_streaming(EmaFilter(params, channel_count(values), fps), values, confidence)
