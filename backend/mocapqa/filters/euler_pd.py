"""PD filters on vector-valued channels: Euler angles, rotation vectors and root positions.

Conventions
-----------
``v ← v + Δt (ω_n² (x̂ − x) − 2ζω_n v + κA Δ²x̂/Δt²)``, ``x ← x + Δt v`` per channel, with the
same natural-frequency / damping parametrisation and stability check as
:mod:`mocapqa.filters.quat_pd` (there ``vec(q̂ ⊗ q*)`` is half the angle, hence its factor 2).
Euler-angle PD (unwrapped per channel with ``np.unwrap``, so ±180° wraps do not jump) and
axis-angle PD (rotation vectors of a hemisphere-continuous quaternion sequence) exist only as
ablation baselines for the quaternion filter; the root translation of a BVH take is filtered
with the same PD and Euler integration, as in QuaMo.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray, check_shape
from mocapqa.filters.quat_pd import QuatPDParams, pd_gains
from mocapqa.kinematics.euler import euler_from_quats, quats_from_euler
from mocapqa.kinematics.quaternion import canonical, exp_map, log_map, unwrap

__all__ = ["axis_angle_pd_filter", "euler_pd_filter", "vector_pd_filter"]


def vector_pd_filter(values: FloatArray, fps: float, params: QuatPDParams) -> FloatArray:
    """PD-track each channel of ``values`` ``(F, ...)``; returns the same shape.

    Parameters
    ----------
    values : ndarray, shape (F, ...)
        Reference signal (finite), any unit.
    fps : float
        Frames per second.
    params : QuatPDParams
        Natural frequency, damping, acceleration share and stability policy
        (``integration`` is ignored: the channels are Euclidean).

    Returns
    -------
    ndarray, shape (F, ...)
    """
    values = np.asarray(values, dtype=np.float64)
    n = values.shape[0]
    ref = values.reshape(n, -1)
    stiffness, damping = pd_gains(
        params.natural_frequency_hz, params.damping_ratio, fps, params.on_unstable
    )
    dt = 1.0 / fps
    ka = params.accel_gain * fps * fps
    out = np.empty_like(ref)
    if n == 0:
        return values.copy()
    x = ref[0].copy()
    v = np.zeros_like(x)
    out[0] = x
    step_prev = np.zeros_like(x)
    for t in range(1, n):
        step = ref[t] - ref[t - 1]
        acc = stiffness * (ref[t] - x) - damping * v
        if ka:
            acc = acc + ka * (step - step_prev)
        v = v + dt * acc
        x = x + dt * v
        out[t] = x
        step_prev = step
    return out.reshape(values.shape)


def euler_pd_filter(
    quats: FloatArray, orders: list[str] | tuple[str, ...], fps: float, params: QuatPDParams
) -> FloatArray:
    """Ablation baseline: PD on unwrapped Euler angles of each joint.

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Noisy unit quaternions.
    orders : sequence of str, length J
        Intrinsic Euler order per joint (e.g. "ZXY").
    fps : float
        Frames per second.
    params : QuatPDParams
        Gains.

    Returns
    -------
    ndarray, shape (F, J, 4)
    """
    check_shape(np.asarray(quats), "quats", ("F", len(orders), 4))
    out = np.empty_like(quats)
    for j, order in enumerate(orders):
        if len(order) != 3:
            out[:, j] = quats[:, j]
            continue
        angles = np.unwrap(euler_from_quats(quats[:, j], order), axis=0)
        out[:, j] = quats_from_euler(vector_pd_filter(angles, fps, params), order)
    return out


def axis_angle_pd_filter(quats: FloatArray, fps: float, params: QuatPDParams) -> FloatArray:
    """Ablation baseline: PD on rotation vectors of ``(F, J, 4)`` quats; returns ``(F, J, 4)``."""
    continuous = unwrap(np.asarray(quats, dtype=np.float64))
    # Start in the w >= 0 hemisphere, else a joint near identity sits near angle 2π, where
    # the rotation vector is singular.
    first = np.sum(canonical(continuous[:1]) * continuous[:1], axis=-1, keepdims=True)
    rotvecs = log_map(continuous * np.sign(first))
    return exp_map(vector_pd_filter(rotvecs, fps, params))
