"""Running a streaming filter over a whole array, so batch output equals streaming output.

Every per-sample filter here (EMA, One Euro, ...) exposes ``update(values, confidence)`` for
one frame and a ``bridged`` mask for that frame; :func:`run_streaming` is their batch form.
Time is axis 0; the remaining axes are flattened into channels and restored on return.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray

__all__ = ["StreamingFilter", "channel_count", "run_streaming"]


class StreamingFilter(Protocol):
    """A filter updated one frame at a time over a fixed number of channels."""

    @property
    def bridged(self) -> BoolArray:
        """Channels of the last frame that were predicted, not measured."""
        ...

    def update(self, values: FloatArray, confidence: FloatArray | None = None) -> FloatArray:
        """Filter one frame ``(C,)`` and return the filtered values ``(C,)``."""
        ...


def channel_count(values: FloatArray) -> int:
    """Number of channels of ``values (F, ...)``: the product of all axes after time."""
    return int(np.prod(np.shape(values)[1:], dtype=np.int64))


def run_streaming(
    stream: StreamingFilter, values: FloatArray, confidence: FloatArray | None
) -> tuple[FloatArray, BoolArray]:
    """Run a fresh streaming filter frame by frame over ``values``.

    Parameters
    ----------
    stream : StreamingFilter
        A new filter built for :func:`channel_count` ``(values)`` channels.
    values : ndarray, shape (F, ...)
        Samples, NaN where missing.
    confidence : ndarray, shape (F, ...), optional
        Per-sample confidence.

    Returns
    -------
    filtered : ndarray, shape (F, ...)
    bridged : ndarray of bool, shape (F, ...)
    """
    values = np.asarray(values, dtype=np.float64)
    n = values.shape[0]
    flat = values.reshape(n, -1)
    conf = None if confidence is None else np.asarray(confidence, np.float64).reshape(n, -1)
    out = np.empty_like(flat)
    bridged = np.empty(flat.shape, dtype=bool)
    for t in range(n):
        out[t] = stream.update(flat[t], None if conf is None else conf[t])
        bridged[t] = stream.bridged
    return out.reshape(values.shape), bridged.reshape(values.shape)
