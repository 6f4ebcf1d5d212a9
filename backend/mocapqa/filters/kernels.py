"""Compiled per-frame kernels of the adaptive blend and the quaternion PD filter.

Conventions
-----------
The recursive filters loop over time; a NumPy step costs about a microsecond per array
operation whatever the array size, which caps a 33-keypoint blend near 0.1 M samples/s. These
``numba`` kernels do the same arithmetic channel by channel in compiled loops. Each has a
single-frame step, used by the streaming classes, and a batch loop that calls the very same
step, so streaming and batch give bit-identical output. The arithmetic mirrors
:mod:`mocapqa.filters.kalman`, :mod:`mocapqa.filters.one_euro`, :mod:`mocapqa.filters.ema` and
:mod:`mocapqa.filters.quat_pd` (tests compare them). State arrays are updated in place; they are
the filters' own state, never the caller's inputs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mocapqa.core.arrays import BoolArray, FloatArray

__all__ = [
    "adaptive_batch",
    "adaptive_frame",
    "adaptive_step",
    "quat_pd_batch",
    "quat_pd_step",
]


def _adaptive_frame(
    z: FloatArray,
    c: FloatArray,
    settings: FloatArray,
    kstate: FloatArray,
    krun: FloatArray,
    other: FloatArray,
    mse: FloatArray,
    out: FloatArray,
    weights: FloatArray,
    bridged: BoolArray,
    scratch: FloatArray,
    drift: FloatArray,
) -> None:
    """One frame of the innovation-weighted blend over ``N = 3K`` channels, in place.

    Kept whole because it is the compiled body of both the streaming step and the batch loop:
    the body drift, the Kalman, One Euro and EMA updates and the blend share passes over the
    channels with the ~25 unpacked settings held in local variables, and splitting it into
    separately compiled functions would pass those through every call on the per-frame path
    and risk reordering floating-point operations whose results the streaming and batch
    outputs, and the reference filters the tests compare them with, must match bit for bit.

    Parameters
    ----------
    z : ndarray, shape (N,)
        Measurements, NaN where missing.
    c : ndarray, shape (K,)
        Confidence per keypoint (shared by its three channels).
    settings : ndarray, shape (23,)
        Packed parameters, see :func:`mocapqa.filters.adaptive.pack_settings`.
    kstate : ndarray, shape (6, N)
        Kalman position, velocity, P00, P01, P11 and started flag.
    krun : ndarray, shape (N,)
        Consecutive gated samples per channel.
    other : ndarray, shape (3, N)
        One Euro value, One Euro derivative and EMA value.
    mse : ndarray, shape (K, 3)
        Innovation averages per keypoint and filter.
    out : ndarray, shape (N,)
        Blended output (written).
    weights : ndarray, shape (K, 3)
        Weights (written).
    bridged : ndarray of bool, shape (K,)
        True where the Kalman filter bridged any of the keypoint's channels (written).
    scratch : ndarray, shape (6, N)
        Work space: squared innovations and filter outputs (overwritten).
    drift : ndarray, shape (2, 3)
        Work space: body velocity sums and counts per axis (overwritten).
    """
    dt, fps = settings[0], settings[1]
    q00, q01, q11 = settings[2], settings[3], settings[4]
    mr, cw, kminc, gate2 = settings[5], settings[6], settings[7], settings[8]
    reacq_n, decay_v = settings[9], settings[10]
    alpha_d, minw, betaw, ominc = settings[11], settings[12], settings[13], settings[14]
    ema_alpha, aminc, share = settings[15], settings[16], settings[17]
    decay_w, floor, power, lead = settings[18], settings[19], settings[20], settings[21]
    body_prior = settings[22]
    n = z.shape[0]
    k = n // 3
    sq = scratch[0:3]
    xs = scratch[3:6]
    body = drift[0]
    count = drift[1]
    # Mean velocity per axis of the started channels: the whole body's drift, toward which a
    # bridged channel's velocity relaxes (a walking person's hidden wrist keeps walking).
    for d in range(3):
        body[d] = 0.0
        count[d] = 0.0
    for kp in range(k):
        bridged[kp] = False
    for i in range(n):
        if kstate[5, i] > 0.5:
            body[i % 3] += kstate[1, i]
            count[i % 3] += 1.0
    for d in range(3):
        body[d] = body[d] / count[d] if count[d] > 0 else 0.0
    for kp in range(k):
        # Confidence, and so the measurement noise, is shared by a keypoint's channels.
        ci = c[kp]
        r = mr / max(ci * ci, 1e-6) if cw > 0.5 else mr
        for d in range(3):
            i = 3 * kp + d
            x0, x1 = kstate[0, i], kstate[1, i]
            started = kstate[5, i] > 0.5
            pred_k = x0 + dt * x1 if started else np.nan
            pos = x0 + dt * x1
            vel = x1
            p00 = kstate[2, i] + 2.0 * dt * kstate[3, i] + dt * dt * kstate[4, i] + q00
            p01 = kstate[3, i] + dt * kstate[4, i] + q01
            p11 = kstate[4, i] + q11
            zi = z[i]
            valid = (not math.isnan(zi)) and ci > kminc
            if valid and not started:
                pos, vel, p00, p01, p11 = zi, 0.0, r, 0.0, 100.0 * q11
                started = True
            y = zi - pos if valid else 0.0
            s = p00 + r
            if gate2 > 0.0:
                inside = y * y <= gate2 * s
                reacquire = valid and (not inside) and krun[i] >= reacq_n
                if reacquire:
                    p00 += y * y
                    p11 += y * y * (0.5 / dt) ** 2
                    s = p00 + r
                gated = valid and (not inside) and (not reacquire)
                krun[i] = krun[i] + 1.0 if gated else 0.0
                if gated:
                    valid = False
                    y = 0.0
            g0 = p00 / s if valid else 0.0
            g1 = p01 / s if valid else 0.0
            pos += g0 * y
            vel += g1 * y
            if (not valid) and decay_v < 1.0:
                target = body[i % 3] if body_prior > 0.5 else 0.0
                vel = target + decay_v * (vel - target)
            p11 -= g1 * p01
            p01 *= 1.0 - g0
            p00 *= 1.0 - g0
            kstate[0, i], kstate[1, i] = pos, vel
            kstate[2, i], kstate[3, i], kstate[4, i] = p00, p01, p11
            kstate[5, i] = 1.0 if started else 0.0
            xk = pos if started else np.nan
            if not valid:
                bridged[kp] = True
            zo, co = zi, ci
            if share > 0.5 and not valid:
                zo, co = xk, 1.0
            # One Euro.
            prev = other[0, i]
            pred_e = prev
            ok = (not math.isnan(zo)) and co > ominc
            if ok:
                if math.isnan(prev):
                    prev = zo
                dxh = other[1, i] + alpha_d * ((zo - prev) * fps - other[1, i])
                cutoff = minw + betaw * abs(dxh)
                other[0, i] = prev + cutoff / (cutoff + fps) * (zo - prev)
                other[1, i] = dxh
            # EMA.
            prev = other[2, i]
            pred_a = prev
            if (not math.isnan(zo)) and co > aminc:
                if math.isnan(prev):
                    prev = zo
                other[2, i] = prev + ema_alpha * (zo - prev)
            xs[0, i], xs[1, i], xs[2, i] = xk, other[0, i], other[2, i]
            ek, ee, ea = zi - pred_k, zi - pred_e, zi - pred_a
            sq[0, i], sq[1, i], sq[2, i] = ek * ek, ee * ee, ea * ea
            if not (valid and not (math.isnan(ek) or math.isnan(ee) or math.isnan(ea))):
                sq[0, i] = np.nan
    for kp in range(k):
        good = True
        for d in range(3):
            if math.isnan(sq[0, 3 * kp + d]):
                good = False
        total = 0.0
        for f in range(3):
            if good:
                err = sq[f, 3 * kp] + sq[f, 3 * kp + 1] + sq[f, 3 * kp + 2]
                mse[kp, f] = decay_w * mse[kp, f] + (1.0 - decay_w) * err
            m = mse[kp, f] + floor
            # Integer powers by multiplication: pow() dominated the step's cost.
            if power == 1.0:
                w = 1.0 / m
            elif power == 2.0:
                w = 1.0 / (m * m)
            elif power == 3.0:
                w = 1.0 / (m * m * m)
            else:
                w = m**-power
            weights[kp, f] = w
            total += w
        for f in range(3):
            weights[kp, f] /= total
        for d in range(3):
            i = 3 * kp + d
            blend = weights[kp, 0] * xs[0, i] + weights[kp, 1] * xs[1, i]
            out[i] = blend + weights[kp, 2] * xs[2, i] + lead * kstate[1, i]


# Compiled kernel: one frame of the blend with caller-owned work space (see _adaptive_frame).
adaptive_frame = njit(cache=True)(_adaptive_frame)


def _adaptive_step(
    z: FloatArray,
    c: FloatArray,
    settings: FloatArray,
    kstate: FloatArray,
    krun: FloatArray,
    other: FloatArray,
    mse: FloatArray,
    out: FloatArray,
    weights: FloatArray,
    bridged: BoolArray,
) -> None:
    """:func:`adaptive_frame` with its own work space (arguments as there)."""
    n = z.shape[0]
    adaptive_frame(
        z,
        c,
        settings,
        kstate,
        krun,
        other,
        mse,
        out,
        weights,
        bridged,
        np.empty((6, n)),
        np.empty((2, 3)),
    )


# Compiled kernel: one frame of the innovation-weighted blend (see _adaptive_step).
adaptive_step = njit(cache=True)(_adaptive_step)


def _adaptive_batch(
    z: FloatArray,
    c: FloatArray,
    settings: FloatArray,
    kstate: FloatArray,
    krun: FloatArray,
    other: FloatArray,
    mse: FloatArray,
    out: FloatArray,
    weights: FloatArray,
    bridged: BoolArray,
) -> None:
    """:func:`adaptive_frame` over frames: ``z, out`` are ``(F, N)``, ``c, bridged`` ``(F, K)``.

    The work space is allocated once for all frames.
    """
    scratch = np.empty((6, z.shape[1]))
    drift = np.empty((2, 3))
    for t in range(z.shape[0]):
        adaptive_frame(
            z[t],
            c[t],
            settings,
            kstate,
            krun,
            other,
            mse,
            out[t],
            weights[t],
            bridged[t],
            scratch,
            drift,
        )


# Compiled kernel: frames of the blend, each by adaptive_frame (see _adaptive_batch).
adaptive_batch = njit(cache=True)(_adaptive_batch)


def _quat_pd_step(
    ref: FloatArray,
    settings: FloatArray,
    quats: FloatArray,
    omega: FloatArray,
    ref1: FloatArray,
    ref_step: FloatArray,
    out: FloatArray,
) -> None:
    """One frame of the quaternion PD filter over ``J`` joints, in place.

    Parameters
    ----------
    ref : ndarray, shape (J, 4)
        Reference quaternions of this frame.
    settings : ndarray, shape (5,)
        ``dt``, ``κP``, ``κD``, ``κA`` and 1.0 for exact integration (0.0 approximate).
    quats, omega, ref1, ref_step : ndarray
        State: filter quats ``(J, 4)``, angular velocity ``(J, 3)``, previous reference
        ``(J, 4)`` and previous reference step ``(J, 3)``.
    out : ndarray, shape (J, 4)
        Output quaternions (written).
    """
    dt, kp, kd, ka, exact = settings[0], settings[1], settings[2], settings[3], settings[4]
    for j in range(ref.shape[0]):
        rx, ry, rz, rw = ref[j, 0], ref[j, 1], ref[j, 2], ref[j, 3]
        px, py, pz, pw = ref1[j, 0], ref1[j, 1], ref1[j, 2], ref1[j, 3]
        if rx * px + ry * py + rz * pz + rw * pw < 0.0:
            rx, ry, rz, rw = -rx, -ry, -rz, -rw
        # vec(r ⊗ p*) = p_w r_v − r_w p_v − r_v × p_v
        sx = pw * rx - rw * px - (ry * pz - rz * py)
        sy = pw * ry - rw * py - (rz * px - rx * pz)
        sz = pw * rz - rw * pz - (rx * py - ry * px)
        qx, qy, qz, qw = quats[j, 0], quats[j, 1], quats[j, 2], quats[j, 3]
        tx, ty, tz, tw = rx, ry, rz, rw
        if tx * qx + ty * qy + tz * qz + tw * qw < 0.0:
            tx, ty, tz, tw = -tx, -ty, -tz, -tw
        ex = qw * tx - tw * qx - (ty * qz - tz * qy)
        ey = qw * ty - tw * qy - (tz * qx - tx * qz)
        ez = qw * tz - tw * qz - (tx * qy - ty * qx)
        wx = omega[j, 0] + dt * (kp * ex - kd * omega[j, 0] + ka * (sx - ref_step[j, 0]))
        wy = omega[j, 1] + dt * (kp * ey - kd * omega[j, 1] + ka * (sy - ref_step[j, 1]))
        wz = omega[j, 2] + dt * (kp * ez - kd * omega[j, 2] + ka * (sz - ref_step[j, 2]))
        hx, hy, hz = 0.5 * dt * wx, 0.5 * dt * wy, 0.5 * dt * wz
        if exact > 0.5:
            angle = math.sqrt(hx * hx + hy * hy + hz * hz)
            scale = 1.0 - angle * angle / 6.0 if angle < 1e-8 else math.sin(angle) / angle
            ax, ay, az, aw = hx * scale, hy * scale, hz * scale, math.cos(angle)
        else:
            ax, ay, az, aw = hx, hy, hz, 0.0
        nx = aw * qx + ax * qw + ay * qz - az * qy
        ny = aw * qy - ax * qz + ay * qw + az * qx
        nz = aw * qz + ax * qy - ay * qx + az * qw
        nw = aw * qw - ax * qx - ay * qy - az * qz
        if exact <= 0.5:
            nx, ny, nz, nw = qx + nx, qy + ny, qz + nz, qw + nw
            norm = math.sqrt(nx * nx + ny * ny + nz * nz + nw * nw)
            nx, ny, nz, nw = nx / norm, ny / norm, nz / norm, nw / norm
        quats[j, 0], quats[j, 1], quats[j, 2], quats[j, 3] = nx, ny, nz, nw
        omega[j, 0], omega[j, 1], omega[j, 2] = wx, wy, wz
        ref1[j, 0], ref1[j, 1], ref1[j, 2], ref1[j, 3] = rx, ry, rz, rw
        ref_step[j, 0], ref_step[j, 1], ref_step[j, 2] = sx, sy, sz
        out[j, 0], out[j, 1], out[j, 2], out[j, 3] = nx, ny, nz, nw


# Compiled kernel: one frame of the quaternion PD filter (see _quat_pd_step).
quat_pd_step = njit(cache=True)(_quat_pd_step)


def _quat_pd_batch(
    refs: FloatArray,
    settings: FloatArray,
    quats: FloatArray,
    omega: FloatArray,
    ref1: FloatArray,
    ref_step: FloatArray,
    out: FloatArray,
) -> None:
    """:func:`quat_pd_step` over frames: ``refs`` and ``out`` are ``(F, J, 4)``."""
    for t in range(refs.shape[0]):
        quat_pd_step(refs[t], settings, quats, omega, ref1, ref_step, out[t])


# Compiled kernel: frames of the quaternion PD filter, each by quat_pd_step.
quat_pd_batch = njit(cache=True)(_quat_pd_batch)
