"""Adaptive blend of a Kalman, a One Euro and an EMA filter per keypoint.

Conventions
-----------
``x̂ = w_K x̂_Kalman + w_E x̂_OneEuro + w_A x̂_EMA`` per keypoint, weights ≥ 0 summing to 1,
returned per frame as a ``(K, 3)`` array in the order of :data:`WEIGHT_NAMES`.

Two weighting modes:

* ``"rules"`` — the adaptive multi-filter note's rules on the motion state
  (:mod:`mocapqa.filters.motion_state`): speed below ``slow_speed`` → (0.2, 0.2, 0.6), below
  ``fast_speed`` → (0.25, 0.55, 0.2), else (0.5, 0.4, 0.1); jitter above
  ``jitter_threshold`` → K −0.2, E +0.1, A +0.1; confidence below ``confidence_threshold`` →
  K +0.2, E −0.1, A −0.1; then clipped at 0 and renormalised (the note leaves negative weights
  unspecified).
* ``"innovation"`` — each filter's weight is proportional to
  ``(mean squared one-step innovation)^−innovation_power`` over the window (an exponential
  average on reliable samples), so the filter that has been predicting the measurements best
  recently gets the most weight. The alternative, fixed rules, needs thresholds tied to one
  data set.

With ``share_bridges`` the One Euro and EMA filters receive the Kalman estimate where the Kalman
filter rejected or missed a sample, so gated outliers and gaps do not reach them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, check_shape
from mocapqa.errors import InputError
from mocapqa.filters.ema import EmaFilter, EmaParams
from mocapqa.filters.kalman import KalmanFilter, KalmanParams
from mocapqa.filters.motion_state import MotionStateTracker
from mocapqa.filters.one_euro import OneEuroFilter, OneEuroParams
from mocapqa.filters.ranges import (
    DURATION,
    DURATION_OR_OFF,
    NON_NEGATIVE,
    POWER,
    UNIT_INTERVAL,
    bounded,
    check_ranges,
)

__all__ = [
    "WEIGHT_NAMES",
    "AdaptiveFilter",
    "AdaptiveParams",
    "AdaptiveResult",
    "adaptive_filter",
    "pack_settings",
    "rule_weights",
]

WEIGHT_NAMES = ("kalman", "one_euro", "ema")
"""Names of the blended filters, in the order of the weight arrays' last axis."""

_RULE_BASE = np.array([[0.2, 0.2, 0.6], [0.25, 0.55, 0.2], [0.5, 0.4, 0.1]])
_JITTER_SHIFT = np.array([-0.2, 0.1, 0.1])
_CONFIDENCE_SHIFT = np.array([0.2, -0.1, -0.1])


@dataclass(frozen=True, slots=True)
class AdaptiveParams:
    """Parameters of the adaptive blend.

    Parameters
    ----------
    kalman, one_euro, ema : KalmanParams, OneEuroParams, EmaParams
        The three member filters.
    weighting : {"rules", "innovation"}
        How weights are chosen (see the module docstring).
    window_s : float
        Motion-state window (rules) or innovation averaging time constant, seconds (0.0001
        to 60).
    slow_speed, fast_speed : float
        Speed thresholds of the rules, unit/s of the data.
    jitter_threshold : float
        Jitter score above which the rules add smoothing, [0, 1].
    confidence_threshold : float
        Confidence below which the rules favour the Kalman filter.
    innovation_power : float
        Exponent of the innovation weighting (> 0 and at most 10).
    share_bridges : bool
        Feed the Kalman estimate to the other filters where it bridged a sample.
    lead_s : float
        Innovation mode only: add ``lead_s`` × the Kalman velocity to the blend, seconds (0 to
        60). It offsets the lag of the smoothing members at the cost of some noise.
    body_prior : bool
        Innovation mode only: while a keypoint is bridged its velocity relaxes (with the Kalman
        ``bridge_decay_s``) toward the mean velocity of all keypoints instead of toward zero.
    """

    kalman: KalmanParams = field(default_factory=KalmanParams)
    one_euro: OneEuroParams = field(default_factory=OneEuroParams)
    ema: EmaParams = field(default_factory=EmaParams)
    weighting: Literal["rules", "innovation"] = "rules"
    window_s: float = bounded(5 / 30, DURATION)
    slow_speed: float = bounded(0.1, NON_NEGATIVE)
    fast_speed: float = bounded(1.0, NON_NEGATIVE)
    jitter_threshold: float = bounded(0.5, UNIT_INTERVAL)
    confidence_threshold: float = bounded(0.5, UNIT_INTERVAL)
    innovation_power: float = bounded(1.0, POWER)
    share_bridges: bool = False
    lead_s: float = bounded(0.0, DURATION_OR_OFF)
    body_prior: bool = False

    def __post_init__(self) -> None:
        check_ranges(self)
        if self.weighting not in ("rules", "innovation"):
            raise InputError(
                f"Expected `weighting` 'rules' or 'innovation', got {self.weighting!r}"
            )
        if not (self.window_s > 0 and 0 <= self.slow_speed <= self.fast_speed):
            raise InputError(
                "Expected `window_s` > 0 and 0 <= `slow_speed` <= `fast_speed`, got "
                f"{self.window_s}, {self.slow_speed} and {self.fast_speed}"
            )
        if not self.innovation_power > 0:
            raise InputError(f"Expected `innovation_power` > 0, got {self.innovation_power}")


def rule_weights(
    speed: FloatArray,
    jitter: FloatArray,
    confidence: FloatArray,
    params: AdaptiveParams,
) -> FloatArray:
    """The note's rule weights ``(K, 3)`` from speed, jitter and confidence ``(K,)`` each."""
    band = (speed >= params.slow_speed).astype(np.intp) + (speed >= params.fast_speed)
    w = _RULE_BASE[band]
    w = w + (jitter > params.jitter_threshold)[:, None] * _JITTER_SHIFT
    w = w + (confidence < params.confidence_threshold)[:, None] * _CONFIDENCE_SHIFT
    w = np.maximum(w, 0.0)
    return np.asarray(w / w.sum(axis=1, keepdims=True))


def pack_settings(params: AdaptiveParams, fps: float) -> FloatArray:
    """The innovation-mode settings as the ``(23,)`` array the compiled kernel reads."""
    dt = 1.0 / fps
    kp, op, ep = params.kalman, params.one_euro, params.ema
    q = kp.process_noise
    decay_v = math.exp(-dt / kp.bridge_decay_s) if kp.bridge_decay_s > 0 else 1.0
    tau_d = 1.0 / (2.0 * math.pi * op.d_cutoff_hz)
    return np.array(
        [
            dt,
            fps,
            q * dt**4 / 4,
            q * dt**3 / 2,
            q * dt**2,
            kp.measurement_noise,
            float(kp.confidence_weighted),
            kp.min_confidence,
            kp.gate_sigma**2,
            float(max(1, round(kp.reacquire_s * fps))),
            decay_v,
            1.0 / (1.0 + tau_d * fps),
            2.0 * math.pi * op.min_cutoff_hz,
            2.0 * math.pi * op.beta,
            op.min_confidence,
            1.0 - math.exp(-dt / ep.time_constant_s),
            ep.min_confidence,
            float(params.share_bridges),
            math.exp(-dt / params.window_s),
            0.01 * kp.measurement_noise,
            params.innovation_power,
            params.lead_s,
            float(params.body_prior),
        ]
    )


@dataclass(frozen=True, slots=True)
class AdaptiveResult:
    """Output of :func:`adaptive_filter`.

    Parameters
    ----------
    values : ndarray, shape (F, K, 3)
        Blended positions.
    weights : ndarray, shape (F, K, 3)
        Weights per frame and keypoint, in the order of :data:`WEIGHT_NAMES`.
    bridged : ndarray of bool, shape (F, K)
        True where the keypoint's sample was missing, low-confidence or rejected.
    """

    values: FloatArray
    weights: FloatArray
    bridged: BoolArray


class AdaptiveFilter:
    """Streaming adaptive blend for ``n_keypoints`` 3D keypoints.

    Parameters
    ----------
    params : AdaptiveParams
        Settings, in the data's units.
    n_keypoints : int
        Number of keypoints ``K``.
    fps : float
        Frames per second.
    max_frames : int, optional
        Most frames that will be filtered, when known (a batch): a motion-state window longer
        than the take then costs memory for the take's frames only (see
        :class:`~mocapqa.filters.motion_state.MotionStateTracker`).
    """

    def __init__(
        self, params: AdaptiveParams, n_keypoints: int, fps: float, max_frames: int | None = None
    ) -> None:
        if not fps > 0:
            raise InputError(f"Expected `fps` > 0, got {fps}")
        n = 3 * n_keypoints
        self.params = params
        self.n_keypoints = n_keypoints
        self.fps = fps
        self.kalman = KalmanFilter(params.kalman, n, fps)
        self.one_euro = OneEuroFilter(params.one_euro, n, fps)
        self.ema = EmaFilter(params.ema, n, fps)
        self.state = MotionStateTracker(n_keypoints, fps, params.window_s, max_frames)
        self.innovation = params.weighting == "innovation"
        """Whether the compiled innovation-weighted kernel runs (else the note's rules)."""
        # Kernel state: equal starting weights; the floor (1 % of r) keeps weights finite.
        self.settings = pack_settings(params, fps)
        self.kernel_state = (
            np.zeros((6, n)),
            np.zeros(n),
            np.vstack((np.full(n, np.nan), np.zeros(n), np.full(n, np.nan))),
            np.full((n_keypoints, 3), params.kalman.measurement_noise),
        )
        """Kalman state, gate run lengths, One Euro/EMA state and innovation averages."""
        self.bridged = np.zeros(n_keypoints, dtype=bool)
        """Whether each keypoint's last sample was bridged."""

    def update(
        self, frame: FloatArray, confidence: FloatArray | None = None
    ) -> tuple[FloatArray, FloatArray]:
        """Filter one frame.

        Parameters
        ----------
        frame : ndarray, shape (K, 3)
            Positions, NaN where missing.
        confidence : ndarray, shape (K,), optional
            Confidence in [0, 1]; None means 1.

        Returns
        -------
        filtered : ndarray, shape (K, 3)
        weights : ndarray, shape (K, 3)
            Weights of (Kalman, One Euro, EMA).
        """
        k = self.n_keypoints
        frame = np.asarray(frame, dtype=np.float64)
        if frame.shape != (k, 3):
            check_shape(frame, "frame", (k, 3))
        if confidence is None:
            conf = np.where(np.isnan(frame).any(axis=1), 0.0, 1.0)
        else:
            conf = np.asarray(confidence, dtype=np.float64)
            if conf.shape != (k,):
                check_shape(conf, "confidence", (k,))
        z = frame.reshape(-1)
        if self.innovation:
            # The batch loop over one frame: the same compiled code as adaptive_filter.
            out = np.empty((1, 3 * k))
            weights = np.empty((1, k, 3))
            flags = np.empty((1, k), dtype=bool)
            from mocapqa.filters.kernels import adaptive_batch  # numba, on first use

            adaptive_batch(
                z[None], conf[None], self.settings, *self.kernel_state, out, weights, flags
            )
            self.bridged = flags[0]
            return out.reshape(k, 3), weights[0]
        c = np.repeat(conf, 3)
        p = self.params
        xk = self.kalman.update(z, c)
        bridged = self.kalman.bridged
        if p.share_bridges:
            z_other = np.where(bridged, xk, z)
            c_other = np.where(bridged, 1.0, c)
        else:
            z_other, c_other = z, c
        outputs = np.stack(
            (xk, self.one_euro.update(z_other, c_other), self.ema.update(z_other, c_other))
        )
        st = self.state.update(frame, conf)
        weights = rule_weights(st.speed, st.jitter, st.confidence, p)
        filtered = (outputs * np.repeat(weights.T, 3, axis=1)).sum(axis=0).reshape(k, 3)
        self.bridged = np.asarray(bridged.reshape(k, 3).any(axis=1))
        return filtered, weights


def adaptive_filter(
    positions: FloatArray,
    fps: float,
    params: AdaptiveParams,
    confidence: FloatArray | None = None,
) -> AdaptiveResult:
    """Filter a keypoint sequence with :class:`AdaptiveFilter` (identical to streaming it).

    Parameters
    ----------
    positions : ndarray, shape (F, K, 3)
        Positions, NaN where missing.
    fps : float
        Frames per second.
    params : AdaptiveParams
        Settings in the data's units.
    confidence : ndarray, shape (F, K), optional
        Confidence per sample.

    Returns
    -------
    AdaptiveResult
    """
    positions = np.asarray(positions, dtype=np.float64)
    check_shape(positions, "positions", ("F", "K", 3))
    n, k, _ = positions.shape
    if confidence is not None:
        check_shape(np.asarray(confidence), "confidence", (n, k))
    f = AdaptiveFilter(params, k, fps, max_frames=n)
    if f.innovation:
        conf = np.ones((n, k)) if confidence is None else np.asarray(confidence, np.float64)
        flat = np.ascontiguousarray(positions.reshape(n, 3 * k))
        out_flat = np.empty((n, 3 * k))
        w = np.empty((n, k, 3))
        bridged = np.empty((n, k), dtype=bool)
        from mocapqa.filters.kernels import adaptive_batch  # numba, on first use

        adaptive_batch(
            flat, np.ascontiguousarray(conf), f.settings, *f.kernel_state, out_flat, w, bridged
        )
        return AdaptiveResult(out_flat.reshape(n, k, 3), w, bridged)
    out = np.empty_like(positions)
    weights = np.empty((n, k, 3))
    bridged = np.empty((n, k), dtype=bool)
    for t in range(n):
        out[t], weights[t] = f.update(positions[t], None if confidence is None else confidence[t])
        bridged[t] = f.bridged
    return AdaptiveResult(out, weights, bridged)
