"""One Euro filter for rotation streams, on the unit-quaternion sphere.

Conventions
-----------
The derivative is the angular velocity ``log(q̂_t ⊗ q_{t−1}*) · fps`` (rad/s, a 3-vector),
low-passed at ``d_cutoff_hz``; the cutoff is ``min_cutoff_hz + beta · |ω̂|`` with ``beta`` in
Hz per rad/s; the output moves from the previous output toward the sample by the fraction
``α`` along the geodesic (``exp(α · log(q̂ ⊗ q*)) ⊗ q``). The reference is flipped into the
previous output's hemisphere first, so sign flips of the input do nothing. The alternative,
One Euro on the four components followed by renormalising, depends on the sign convention.

References
----------
Casiez, G., Roussel, N., Vogel, D. (2012). 1€ Filter. CHI '12. doi:10.1145/2207676.2208639
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray, check_shape
from mocapqa.errors import InputError
from mocapqa.filters.one_euro import check_cutoffs
from mocapqa.filters.ranges import FREQUENCY, NON_NEGATIVE, bounded, check_ranges
from mocapqa.kinematics.quaternion import exp_map, log_map, multiply, unwrap

__all__ = ["QuatOneEuroFilter", "QuatOneEuroParams", "quat_one_euro_filter"]


@dataclass(frozen=True, slots=True)
class QuatOneEuroParams:
    """Parameters of the quaternion One Euro filter.

    Parameters
    ----------
    min_cutoff_hz : float
        Cutoff at rest, Hz.
    beta : float
        Cutoff slope, Hz per rad/s.
    d_cutoff_hz : float
        Cutoff of the angular-velocity low-pass, Hz.
    """

    min_cutoff_hz: float = bounded(1.5, FREQUENCY)
    beta: float = bounded(0.5, NON_NEGATIVE)
    d_cutoff_hz: float = bounded(1.0, FREQUENCY)

    def __post_init__(self) -> None:
        check_ranges(self)
        check_cutoffs(self.min_cutoff_hz, self.d_cutoff_hz, self.beta)


class QuatOneEuroFilter:
    """Streaming quaternion One Euro filter over ``n_joints`` streams.

    Parameters
    ----------
    params : QuatOneEuroParams
        Cutoffs and slope.
    n_joints : int
        Number of streams.
    fps : float
        Frames per second.
    """

    def __init__(self, params: QuatOneEuroParams, n_joints: int, fps: float) -> None:
        if not fps > 0:
            raise InputError(f"Expected `fps` > 0, got {fps}")
        self.params = params
        self.fps = fps
        tau_d = 1.0 / (2.0 * math.pi * params.d_cutoff_hz)
        self._alpha_d = 1.0 / (1.0 + tau_d * fps)
        self.quats = np.zeros((0, 4))
        self.omega = np.zeros((n_joints, 3))

    def update(self, reference: FloatArray) -> FloatArray:
        """Advance one frame with ``(J, 4)`` quaternions; returns ``(J, 4)`` unit quaternions."""
        ref = np.asarray(reference, dtype=np.float64)
        if self.quats.shape[0] == 0:
            self.quats = ref / np.linalg.norm(ref, axis=1, keepdims=True)
            return self.quats.copy()
        q = self.quats
        ref = ref * np.sign(np.einsum("jc,jc->j", ref, q) + 1e-300)[:, None]
        delta = log_map(multiply(ref, np.concatenate((-q[:, :3], q[:, 3:]), axis=1)))
        self.omega = self.omega + self._alpha_d * (delta * self.fps - self.omega)
        speed = np.sqrt(np.einsum("jc,jc->j", self.omega, self.omega))
        cutoff = 2.0 * math.pi * (self.params.min_cutoff_hz + self.params.beta * speed)
        alpha = (cutoff / (cutoff + self.fps))[:, None]
        q = multiply(exp_map(alpha * delta), q)
        self.quats = q / np.linalg.norm(q, axis=1, keepdims=True)
        return self.quats.copy()


def quat_one_euro_filter(quats: FloatArray, fps: float, params: QuatOneEuroParams) -> FloatArray:
    """Filter ``(F, J, 4)`` rotation streams, identical to streaming them; same shape out."""
    quats = np.asarray(quats, dtype=np.float64)
    check_shape(quats, "quats", ("F", "J", 4))
    f = QuatOneEuroFilter(params, quats.shape[1], fps)
    out = np.empty_like(quats)
    for t in range(quats.shape[0]):
        out[t] = f.update(quats[t])
    return unwrap(out)
