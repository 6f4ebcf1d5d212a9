"""Constant-velocity Kalman filter, one independent filter per channel.

Conventions
-----------
State per channel is ``[position, velocity]`` with ``A = [[1, Δt], [0, 1]]``, ``H = [1, 0]`` and
the discrete white-noise-acceleration process noise ``Q = q [[Δt⁴/4, Δt³/2], [Δt³/2, Δt²]]``
(Welch & Bishop 2006; the adaptive multi-filter note). ``q`` is an acceleration variance in
unit²/s⁴ and ``r`` a measurement variance in unit², both in the data's length unit, so a preset
must be converted when the unit changes (see :mod:`mocapqa.filters.registry`).

With ``confidence_weighted`` the measurement variance of a sample is ``r / confidence²``
(a detector's confidence read as an inverse noise scale); the alternative, one ``r`` for every
sample, is the note's form. Samples whose normalised innovation exceeds ``gate_sigma`` are
rejected as outliers. Missing samples (NaN or zero confidence) and rejected ones are bridged by
the prediction and reported as bridged.

The 2×2 covariance is stored as three arrays (``P00, P01, P11``) so one time step is a few
vector operations over every channel; the loop runs over time only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError
from mocapqa.filters.ranges import (
    BELOW_ONE,
    DURATION_OR_OFF,
    NOISE,
    SIGMA,
    bounded,
    check_ranges,
)

__all__ = ["KalmanFilter", "KalmanParams", "KalmanResult", "kalman_filter"]


@dataclass(frozen=True, slots=True)
class KalmanParams:
    """Parameters of the constant-velocity Kalman filter.

    Parameters
    ----------
    process_noise : float
        ``q``, white-acceleration variance, unit²/s⁴ (> 0).
    measurement_noise : float
        ``r``, measurement variance, unit² (> 0).
    confidence_weighted : bool
        Use ``R = r / confidence²`` per sample.
    gate_sigma : float
        Reject samples whose innovation exceeds this many predicted standard deviations;
        0 disables gating.
    min_confidence : float
        Samples with a confidence below this are treated as missing.
    reacquire_s : float
        After this many seconds of consecutive gated samples, a channel accepts the next sample
        with an inflated covariance (so a fast real movement cannot lock the gate shut).
    bridge_decay_s : float
        Time constant (s) with which the velocity decays while a channel is bridged; 0 keeps
        it constant (pure constant-velocity prediction).
    """

    process_noise: float = bounded(1e-2, NOISE)
    measurement_noise: float = bounded(3e-5, NOISE)
    confidence_weighted: bool = False
    gate_sigma: float = bounded(0.0, SIGMA)
    min_confidence: float = bounded(0.0, BELOW_ONE)
    reacquire_s: float = bounded(0.1, DURATION_OR_OFF)
    bridge_decay_s: float = bounded(0.0, DURATION_OR_OFF)

    def __post_init__(self) -> None:
        check_ranges(self)
        if not (self.process_noise > 0 and self.measurement_noise > 0):
            raise InputError(
                "Expected `process_noise` and `measurement_noise` > 0, got "
                f"{self.process_noise} and {self.measurement_noise}"
            )
        if self.gate_sigma < 0 or not 0 <= self.min_confidence < 1:
            raise InputError(
                f"Expected `gate_sigma` >= 0 and `min_confidence` in [0, 1), got "
                f"{self.gate_sigma} and {self.min_confidence}"
            )


@dataclass(frozen=True, slots=True)
class KalmanResult:
    """Output of :func:`kalman_filter`.

    Parameters
    ----------
    values : ndarray, shape (F, ...)
        Filtered positions, NaN only before a channel's first valid sample.
    velocities : ndarray, shape (F, ...)
        Estimated velocities, unit/s.
    bridged : ndarray of bool, shape (F, ...)
        True where the output is a prediction (missing, low-confidence or gated input).
    """

    values: FloatArray
    velocities: FloatArray
    bridged: BoolArray


class KalmanFilter:
    """Streaming constant-velocity Kalman filter over ``n_channels`` independent channels.

    Parameters
    ----------
    params : KalmanParams
        Noise and gating settings.
    n_channels : int
        Number of independent scalar channels.
    fps : float
        Frames per second of the stream.
    """

    def __init__(self, params: KalmanParams, n_channels: int, fps: float) -> None:
        if not fps > 0:
            raise InputError(f"Expected `fps` > 0, got {fps}")
        self.params = params
        dt = 1.0 / fps
        self.dt = dt
        q = params.process_noise
        self._q00, self._q01, self._q11 = q * dt**4 / 4, q * dt**3 / 2, q * dt**2
        self._gate2 = params.gate_sigma**2
        self._reacquire = max(1, round(params.reacquire_s * fps))
        self._gated_run = np.zeros(n_channels, dtype=np.intp)
        self._decay = math.exp(-dt / params.bridge_decay_s) if params.bridge_decay_s > 0 else 1.0
        self._transition = np.array([[1.0, dt], [0.0, 1.0]])
        self._cov_transition = np.array([[1.0, 2 * dt, dt * dt], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
        self._cov_noise = np.array([[self._q00], [self._q01], [self._q11]])
        self.state = np.zeros((2, n_channels))
        """Position and velocity per channel, shape (2, N)."""
        self.cov = np.zeros((3, n_channels))
        """Covariance entries P00, P01, P11 per channel, shape (3, N)."""
        self.started = np.zeros(n_channels, dtype=bool)
        self._all_started = False
        self.innovation = np.zeros(n_channels)
        """Last innovation ``z − prediction`` per channel (0 where no update)."""
        self.bridged = np.zeros(n_channels, dtype=bool)
        """Whether the last output was a prediction."""

    @property
    def position(self) -> FloatArray:
        """Current position estimate ``(N,)``, NaN before a channel's first sample."""
        return np.asarray(np.where(self.started, self.state[0], np.nan))

    @property
    def velocity(self) -> FloatArray:
        """Current velocity estimate ``(N,)``, unit/s."""
        return np.array(self.state[1], dtype=np.float64)

    def prediction(self) -> FloatArray:
        """One-step-ahead position prediction ``(N,)`` (NaN before a channel's first sample)."""
        return np.asarray(np.where(self.started, self.state[0] + self.dt * self.state[1], np.nan))

    def update(self, values: FloatArray, confidence: FloatArray | None = None) -> FloatArray:
        """Advance one frame.

        Parameters
        ----------
        values : ndarray, shape (N,)
            Measurements, NaN where missing.
        confidence : ndarray, shape (N,), optional
            Confidence in [0, 1]; None means 1 everywhere.

        Returns
        -------
        ndarray, shape (N,)
            Filtered positions (a new array; NaN before a channel's first valid sample).
        """
        p = self.params
        state = self._transition @ self.state
        cov = self._cov_transition @ self.cov + self._cov_noise
        missing = np.isnan(values)
        if confidence is None:
            valid = ~missing
            r: FloatArray | float = p.measurement_noise
        else:
            valid = (confidence > p.min_confidence) & ~missing
            if p.confidence_weighted:
                r = p.measurement_noise / np.maximum(confidence * confidence, 1e-6)
            else:
                r = p.measurement_noise
        if not self._all_started:
            fresh = valid & ~self.started
            if fresh.any():
                # First valid sample: the state starts at the measurement with zero velocity.
                rr = np.broadcast_to(r, values.shape)
                state[:, fresh] = np.stack((values[fresh], np.zeros(int(fresh.sum()))))
                cov[:, fresh] = np.stack(
                    (
                        rr[fresh],
                        np.zeros(int(fresh.sum())),
                        np.full(int(fresh.sum()), 100 * self._q11),
                    )
                )
                self.started |= fresh
                self._all_started = bool(self.started.all())
        y = np.where(valid, values - state[0], 0.0)
        s = cov[0] + r
        if self._gate2 > 0:
            inside = y * y <= self._gate2 * s
            reacquire = valid & ~inside & (self._gated_run >= self._reacquire)
            if reacquire.any():
                # Trust the sample again: widen the covariance so position and velocity jump.
                y2 = np.where(reacquire, y * y, 0.0)
                cov[0] += y2
                cov[2] += y2 * (0.5 / self.dt) ** 2
                s = cov[0] + r
            gated = valid & ~inside & ~reacquire
            self._gated_run = np.where(gated, self._gated_run + 1, 0)
            valid &= ~gated
            y = np.where(valid, y, 0.0)
        gain = cov[:2] * (valid / s)
        state += gain * y
        if self._decay < 1.0:
            state[1] = np.where(valid, state[1], state[1] * self._decay)
        d = gain[1] * cov[1]
        cov[:2] *= 1.0 - gain[0]
        cov[2] -= d
        self.state = state
        self.cov = cov
        self.innovation = y
        self.bridged = ~valid
        if self._all_started:
            return np.array(state[0], dtype=np.float64)
        return np.asarray(np.where(self.started, state[0], np.nan))


def kalman_filter(
    values: FloatArray,
    fps: float,
    params: KalmanParams,
    confidence: FloatArray | None = None,
) -> KalmanResult:
    """Filter a whole sequence with :class:`KalmanFilter` (identical to streaming it).

    Parameters
    ----------
    values : ndarray, shape (F, ...)
        Measurements, time on axis 0, NaN where missing.
    fps : float
        Frames per second.
    params : KalmanParams
        Filter settings.
    confidence : ndarray, shape (F, ...), optional
        Per-sample confidence, same shape as ``values``.

    Returns
    -------
    KalmanResult
    """
    values = np.asarray(values, dtype=np.float64)
    n_frames = values.shape[0]
    flat = values.reshape(n_frames, -1)
    conf = None if confidence is None else np.asarray(confidence, np.float64).reshape(n_frames, -1)
    kf = KalmanFilter(params, flat.shape[1], fps)
    out = np.empty_like(flat)
    vel = np.empty_like(flat)
    bridged = np.empty(flat.shape, dtype=bool)
    for t in range(n_frames):
        out[t] = kf.update(flat[t], None if conf is None else conf[t])
        vel[t] = kf.state[1]
        bridged[t] = kf.bridged
    return KalmanResult(
        out.reshape(values.shape), vel.reshape(values.shape), bridged.reshape(values.shape)
    )
