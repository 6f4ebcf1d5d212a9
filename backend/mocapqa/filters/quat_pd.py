"""Quaternion PD kinematics filter for rotation streams (after QuaMo).

Conventions
-----------
State per joint: a unit quaternion ``q`` (scalar-last) and an angular velocity ``ω`` (rad/s,
parent frame, so ``q_{t+1} = exp(Δt ω) ⊗ q_t``). With the noisy reference ``q̂_t`` flipped into
``q``'s hemisphere (the double cover: the shorter error is always taken)::

    ω̇ = κP vec(q̂_t ⊗ q*) − κD ω + κA (vec(q̂_t ⊗ q̂*_{t−1}) − vec(q̂_{t−1} ⊗ q̂*_{t−2}))
    ω ← ω + Δt ω̇
    q ← exp(Δt/2 · ω) ⊗ q            (exact: rotation by |ω|Δt about ω/|ω|)

``integration="approximate"`` replaces the last line by ``q ← normalise(q + Δt/2 · ω ⊗ q)``
for the ablation. The paper learns κ per frame; here they are constants set from a natural
frequency ``f_n`` and a damping ratio ``ζ``: since ``vec(q̂ ⊗ q*) ≈ (θ̂ − θ)/2`` for small
errors, ``κP = 2 (2π f_n)²`` and ``κD = 2 ζ (2π f_n)``. ``accel_gain`` ∈ [0, 1] is the share of
the reference's own angular acceleration fed forward: ``κA = accel_gain · 2/Δt²``.

Stability: the update is semi-implicit Euler, stable for ``h²ω_n² + 4ζ h ω_n < 4`` and
``ζ h ω_n < 1`` (``h = Δt``, ``ω_n = 2π f_n``). Unstable gains are refused with the largest
stable frequency in the message, or clamped to 90 % of it with ``on_unstable="clamp"``.

References
----------
QuaMo: quaternion motions for vision-based 3D human kinematics capture (see
``shared/seeds/quamo-paper.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from mocapqa.core.arrays import FloatArray, check_shape
from mocapqa.errors import InputError
from mocapqa.filters.ranges import FREQUENCY, POSITIVE, UNIT_INTERVAL, bounded, check_ranges
from mocapqa.kinematics.quaternion import unwrap

__all__ = [
    "QuatPDFilter",
    "QuatPDParams",
    "max_stable_frequency_hz",
    "pd_gains",
    "quat_pd_filter",
]


@dataclass(frozen=True, slots=True)
class QuatPDParams:
    """Parameters of the quaternion PD filter.

    Parameters
    ----------
    natural_frequency_hz : float
        Natural frequency of the closed loop, Hz (> 0).
    damping_ratio : float
        Damping ratio ζ (> 0; 1 is critical).
    accel_gain : float
        Share of the reference's angular acceleration fed forward, [0, 1].
    integration : {"exact", "approximate"}
        Exact exponential map on S³, or first-order step plus renormalisation.
    on_unstable : {"refuse", "clamp"}
        What to do with gains the frame rate cannot integrate stably.
    """

    natural_frequency_hz: float = bounded(2.5, FREQUENCY)
    damping_ratio: float = bounded(1.0, POSITIVE)
    accel_gain: float = bounded(0.0, UNIT_INTERVAL)
    integration: Literal["exact", "approximate"] = "exact"
    on_unstable: Literal["refuse", "clamp"] = "refuse"

    def __post_init__(self) -> None:
        check_ranges(self)
        if not (self.natural_frequency_hz > 0 and self.damping_ratio > 0):
            raise InputError(
                "Expected `natural_frequency_hz` > 0 and `damping_ratio` > 0, got "
                f"{self.natural_frequency_hz} and {self.damping_ratio}"
            )
        if not 0 <= self.accel_gain <= 1:
            raise InputError(f"Expected `accel_gain` in [0, 1], got {self.accel_gain}")
        if self.integration not in ("exact", "approximate"):
            raise InputError(
                f"Expected `integration` 'exact' or 'approximate', got {self.integration!r}"
            )
        if self.on_unstable not in ("refuse", "clamp"):
            raise InputError(
                f"Expected `on_unstable` 'refuse' or 'clamp', got {self.on_unstable!r}"
            )


def max_stable_frequency_hz(damping_ratio: float, fps: float) -> float:
    """Largest natural frequency (Hz) the semi-implicit update integrates stably at ``fps``."""
    z = damping_ratio
    h_omega = min(-2.0 * z + 2.0 * math.sqrt(z * z + 1.0), 1.0 / z)
    return h_omega * fps / (2.0 * math.pi)


def pd_gains(
    natural_frequency_hz: float, damping_ratio: float, fps: float, on_unstable: str
) -> tuple[float, float]:
    """Stiffness and damping ``(ω_n², 2ζω_n)`` in 1/s² and 1/s, checked against ``fps``.

    Raises
    ------
    InputError
        If the gains are unstable at ``fps`` and ``on_unstable`` is "refuse".
    """
    limit = max_stable_frequency_hz(damping_ratio, fps)
    f = natural_frequency_hz
    if f >= limit:
        if on_unstable != "clamp":
            raise InputError(
                f"Expected `natural_frequency_hz` < {limit:.3g} Hz for stable integration at "
                f"{fps:g} fps with damping ratio {damping_ratio:g}, got {f:g} Hz "
                "(lower it or pass on_unstable=clamp)"
            )
        f = 0.9 * limit
    omega = 2.0 * math.pi * f
    return omega * omega, 2.0 * damping_ratio * omega


class QuatPDFilter:
    """Streaming quaternion PD filter over ``n_joints`` rotation streams.

    Parameters
    ----------
    params : QuatPDParams
        Gains and integration.
    n_joints : int
        Number of streams.
    fps : float
        Frames per second.
    """

    def __init__(self, params: QuatPDParams, n_joints: int, fps: float) -> None:
        if not fps > 0:
            raise InputError(f"Expected `fps` > 0, got {fps}")
        self.params = params
        self.dt = 1.0 / fps
        self.kp_stiffness, self.kd = pd_gains(
            params.natural_frequency_hz, params.damping_ratio, fps, params.on_unstable
        )
        self.kp = 2.0 * self.kp_stiffness
        self.ka = params.accel_gain * 2.0 * fps * fps
        self.settings = np.array(
            [self.dt, self.kp, self.kd, self.ka, 1.0 if params.integration == "exact" else 0.0]
        )
        self.n_joints = n_joints
        self.started = False
        self.quats = np.zeros((n_joints, 4))
        self.omega = np.zeros((n_joints, 3))
        self.previous_reference = np.zeros((n_joints, 4))
        self.reference_step = np.zeros((n_joints, 3))

    def _start(self, ref: FloatArray) -> FloatArray:
        self.quats = ref / np.linalg.norm(ref, axis=1, keepdims=True)
        self.previous_reference = self.quats.copy()
        self.started = True
        return self.quats.copy()

    def update(self, reference: FloatArray) -> FloatArray:
        """Advance one frame with reference quats ``(J, 4)``; returns unit quats ``(J, 4)``."""
        ref = np.ascontiguousarray(reference, dtype=np.float64)
        check_shape(ref, "reference", (self.n_joints, 4))
        if not self.started:
            return self._start(ref)
        # The batch loop over one frame: the same compiled code as :meth:`run`, so the
        # streaming output is bit-identical to the batch output.
        out = np.empty((1, self.n_joints, 4))
        from mocapqa.filters.kernels import quat_pd_batch  # numba, on first use

        quat_pd_batch(
            ref[None],
            self.settings,
            self.quats,
            self.omega,
            self.previous_reference,
            self.reference_step,
            out,
        )
        return np.array(out[0])

    def run(self, references: FloatArray) -> FloatArray:
        """Advance over ``(F, J, 4)`` references at once; returns ``(F, J, 4)``."""
        refs = np.ascontiguousarray(references, dtype=np.float64)
        out = np.empty_like(refs)
        if refs.shape[0] == 0:
            return out
        start = 0
        if not self.started:
            out[0] = self._start(refs[0])
            start = 1
        from mocapqa.filters.kernels import quat_pd_batch  # numba, on first use

        quat_pd_batch(
            refs[start:],
            self.settings,
            self.quats,
            self.omega,
            self.previous_reference,
            self.reference_step,
            out[start:],
        )
        return out


def quat_pd_filter(quats: FloatArray, fps: float, params: QuatPDParams) -> FloatArray:
    """Filter rotation streams with :class:`QuatPDFilter` (identical to streaming them).

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Noisy unit quaternions; signs may flip between frames.
    fps : float
        Frames per second.
    params : QuatPDParams
        Gains and integration.

    Returns
    -------
    ndarray, shape (F, J, 4)
        Filtered unit quaternions, hemisphere-continuous.
    """
    quats = np.asarray(quats, dtype=np.float64)
    check_shape(quats, "quats", ("F", "J", 4))
    return unwrap(QuatPDFilter(params, quats.shape[1], fps).run(quats))
