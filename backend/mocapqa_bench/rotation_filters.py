"""Rotation filters on real takes with seeded rotation noise, and QuaMo's ablation.

Ground truth is the Bandai takes' local joint rotations; the noise is
:func:`mocapqa_bench.noise.rotation_noise` on every joint (root translation kept true, so the
figures measure rotations only). MPJPE and Accel use forward-kinematics joint positions
(millimetres; the takes are in centimetres). Gains are tuned on the training takes.
"""

from __future__ import annotations

import dataclasses
import itertools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.filters.apply import filter_motion
from mocapqa.filters.butterworth import ButterworthParams, butterworth_quats
from mocapqa.filters.euler_pd import axis_angle_pd_filter, euler_pd_filter
from mocapqa.filters.quat_one_euro import QuatOneEuroParams, quat_one_euro_filter
from mocapqa.filters.quat_pd import QuatPDParams, quat_pd_filter
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.kinematics.forward import world_from_local
from mocapqa.kinematics.quaternion import geodesic_angle
from mocapqa.metrics.smoothness import acceleration_error, mean_distance
from mocapqa_bench.filters import Row, Take
from mocapqa_bench.noise import rotation_noise

__all__ = [
    "RotationCase",
    "clean_change_table",
    "quamo_table",
    "rotation_cases",
    "rotation_table",
    "tune_quat_pd",
]

MM_PER_CM = 10.0
RotMethod = Callable[[FloatArray, Take], FloatArray]


@dataclass(frozen=True, slots=True)
class RotationCase:
    """A take and a seeded noisy copy of its local rotations ``(F, J, 4)``."""

    take: Take
    noisy: FloatArray


def rotation_cases(takes: Sequence[Take], seed: int) -> list[RotationCase]:
    """One noisy copy per take, seeded by ``seed`` and the take's index."""
    return [
        RotationCase(
            t, rotation_noise(t.motion.quats, t.motion.fps, np.random.default_rng([seed, 1000 + i]))
        )
        for i, t in enumerate(takes)
    ]


def _positions(take: Take, quats: FloatArray) -> FloatArray:
    return world_from_local(take.motion.skeleton.parents, quats, take.motion.local_translations())[
        1
    ]


def _score(method: RotMethod, cases: Sequence[RotationCase]) -> Row:
    geo, mpjpe, accel, elapsed, samples = [], [], [], 0.0, 0
    for case in cases:
        start = time.perf_counter()
        out = method(case.noisy, case.take)
        elapsed += time.perf_counter() - start
        samples += out.shape[0] * out.shape[1]
        geo.append(np.degrees(geodesic_angle(out, case.take.motion.quats)).mean())
        pos = _positions(case.take, out)
        mpjpe.append(mean_distance(pos, case.take.positions) * MM_PER_CM)
        accel.append(acceleration_error(pos, case.take.positions) * MM_PER_CM)
    return {
        "geodesic_deg": float(np.mean(geo)),
        "mpjpe_mm": float(np.mean(mpjpe)),
        "accel_mm": float(np.mean(accel)),
        "mjoint_frames_per_s": samples / elapsed / 1e6,
    }


def _pd(p: QuatPDParams) -> RotMethod:
    return lambda q, t: quat_pd_filter(q, t.motion.fps, p)


def _euler(p: QuatPDParams) -> RotMethod:
    def run(q: FloatArray, t: Take) -> FloatArray:
        sk = t.motion.skeleton
        orders = [sk.rotation_order(j) for j in range(sk.n_joints)]
        return euler_pd_filter(q, orders, t.motion.fps, p)

    return run


def tune_quat_pd(train: Sequence[RotationCase]) -> QuatPDParams:
    """Natural frequency and damping of the quaternion PD with the lowest training MPJPE."""
    best: tuple[float, QuatPDParams] | None = None
    for f, z in itertools.product((1.0, 1.5, 2.0, 2.5, 3.0, 3.5), (0.7, 1.0)):
        p = QuatPDParams(natural_frequency_hz=f, damping_ratio=z, on_unstable="clamp")
        score = _score(_pd(p), train)["mpjpe_mm"]
        if best is None or score < best[0]:
            best = (score, p)
    return best[1] if best else QuatPDParams()


def rotation_table(test: Sequence[RotationCase], tuned: QuatPDParams) -> list[Row]:
    """Raw, quaternion PD (default and tuned), quaternion One Euro and Butterworth on ``test``."""
    methods: list[tuple[str, RotMethod]] = [
        ("raw", lambda q, t: q),
        ("quat-pd (default)", _pd(QuatPDParams())),
        (
            f"quat-pd (tuned {tuned.natural_frequency_hz:g} Hz, ζ {tuned.damping_ratio:g})",
            _pd(tuned),
        ),
        ("quat-one-euro", lambda q, t: quat_one_euro_filter(q, t.motion.fps, QuatOneEuroParams())),
        (
            "butterworth (offline)",
            lambda q, t: butterworth_quats(q, t.motion.fps, ButterworthParams()),
        ),
    ]
    return [{"method": name, **_score(m, test)} for name, m in methods]


def clean_change_table(takes: Sequence[Take]) -> list[Row]:
    """What each rotation filter, with its defaults, changes on the takes as recorded.

    No noise is added: the change is the filter's lag and smoothing of real motion, which a
    user pays on a clean take. Per method, over every frame and joint with rotation channels
    of ``takes`` (a bind-pose first frame left out): the median change of a local rotation, the
    largest per-joint median (the most-changed joint, typically a thigh) and the 95th
    percentile, degrees.
    """
    rows: list[Row] = []
    for method in ("quat-pd", "quat-one-euro", "euler-pd", "butterworth"):
        changes, joint_medians = [], []
        for take in takes:
            motion = take.motion
            skip = leading_bind_pose(motion.quats)
            rotating = [j for j in range(motion.skeleton.n_joints)
                        if motion.skeleton.rotation_order(j)]  # fmt: skip
            filtered = filter_motion(motion, method)
            angles = np.rad2deg(
                geodesic_angle(motion.quats[skip:, rotating], filtered.quats[skip:, rotating])
            )
            changes.append(angles.ravel())
            joint_medians.append(np.median(angles, axis=0))
        every = np.concatenate(changes)
        rows.append({
            "method": method,
            "median change °": float(np.median(every)),
            "most-changed joint, median °": float(np.max(np.concatenate(joint_medians))),
            "95th percentile °": float(np.percentile(every, 95)),
        })  # fmt: skip
    return rows


def quamo_table(test: Sequence[RotationCase], params: QuatPDParams) -> list[Row]:
    """QuaMo's ablation on ``test``: representation, integration and acceleration term."""
    approx = dataclasses.replace(params, integration="approximate")
    accel = dataclasses.replace(params, accel_gain=0.5)
    accel_small = dataclasses.replace(params, accel_gain=0.1)
    methods: list[tuple[str, RotMethod]] = [
        ("quaternion PD, exact", _pd(params)),
        ("quaternion PD, approximate", _pd(approx)),
        ("quaternion PD, exact + accel 0.1", _pd(accel_small)),
        ("quaternion PD, exact + accel 0.5", _pd(accel)),
        ("Euler PD (file order)", _euler(params)),
        ("axis-angle PD", lambda q, t: axis_angle_pd_filter(q, t.motion.fps, params)),
    ]
    return [{"method": name, **_score(m, test)} for name, m in methods]
