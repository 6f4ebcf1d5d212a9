"""``mocapqa bench feet``, foot cleanup: slides injected through the leg into the held-back
takes' contacts, then ``feet fix --apply all`` (the lock holding the sole under the pivot, with
the heights of the check of the injected take); what is left of each slide and what else
changed."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.feet.check import FeetReport, check_feet
from mocapqa.feet.contacts import Contact
from mocapqa.feet.fix import FootRig, LockResult, foot_rig, lock_feet, shift_ankles
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.ik import leg_subtree
from mocapqa.feet.inject import leg_slide_offsets
from mocapqa.feet.lock import BLEND_S, Lock, sole_heights
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES, FootPoints
from mocapqa.feet.tracks import horizontal_axes
from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import geodesic_angle
from mocapqa.pipeline.feet import motion_foot_points
from mocapqa_bench.feet import (
    ASSUMED_HEIGHT_CM,
    CM_FAMILIES,
    CM_TAKES,
    MIN_CONTACT_S,
    BenchTake,
    overlapping_size,
)
from mocapqa_bench.limits import corpus_files

__all__ = ["CLEANUP_SLIDES_CM", "CleanupTrial", "cleanup_trials", "held_back_cleanup"]

CLEANUP_SLIDES_CM = (2.0, 5.0, 8.0)
"""Slides injected into the legs of the held-back takes before the foot lock, centimetres."""


@dataclass(frozen=True, slots=True)
class CleanupTrial:
    """One slide injected through a leg, then ``feet fix --apply all``.

    Parameters
    ----------
    take, family, foot : str
    size_cm : float
        Injected slide.
    clean_cm, injected_cm, fixed_cm : float
        The check's travel of the contact (skate measure with no threshold) on the clean
        take, the injected one and the fixed one, centimetres.
    fixed_joints_cm : float
        The fixed one's travel read at the joints (``sole_pivot`` False) instead of the sole
        under them, which the lock holds, centimetres.
    hip_knee_deg_blends : float
        Largest change of a hip or knee local rotation in the blend frames (outside the
        locked contacts), degrees.
    hip_knee_deg_outside : float
        The same outside the locked contacts and their blends (0 by construction).
    upper_body_changed : int
        Joints outside the legs whose world position changed in any frame.
    pop_cm_s : dict of str to float
        Per anchor ("middle", "start"), the largest speed the lock adds to an ankle in a
        blend frame, cm/s.
    clamped_frames, locked_frames : int
        Solved foot-frames out of the leg's reach, and all solved foot-frames.
    cpu_s : float
        CPU seconds of the lock (forward kinematics, IK, the travel after).
    """

    take: str
    family: str
    foot: str
    size_cm: float
    clean_cm: float
    injected_cm: float
    fixed_cm: float
    fixed_joints_cm: float
    hip_knee_deg_blends: float
    hip_knee_deg_outside: float
    upper_body_changed: int
    pop_cm_s: dict[str, float]
    clamped_frames: int
    locked_frames: int
    cpu_s: float


def _travel_cm(
    motion: Motion, up: UpAxis, params: FeetParams, foot: str, start: int, end: int, scale: float
) -> float:
    """The check's travel (skate with no threshold) of ``foot`` over motion frames
    ``start..end``, centimetres."""
    points, skipped = motion_foot_points(motion)
    report = check_feet(points, dataclasses.replace(params, skate_travel=0.0), up)
    return overlapping_size(report.findings, "skate", foot, start - skipped, end - skipped) * scale


@dataclass(frozen=True, slots=True)
class _CleanupTake:
    """A clean take of the foot-lock trials, read and checked once for all its slides.

    ``scale`` turns the take's length unit into centimetres; ``legs`` marks the joints of both
    legs, shape (J,); ``hip_knee`` lists the hip and knee joints of each leg; ``blend`` is the
    blend in frames; ``plant`` the planted-foot speed in the take's unit per second.
    """

    path: Path
    family: str
    params: FeetParams
    motion: Motion
    points: FootPoints
    skipped: int
    scale: float
    clean: FeetReport
    rig: FootRig
    legs: BoolArray
    hip_knee: list[int]
    blend: int
    flat_axes: list[int]
    plant: float


def _cleanup_take(path: Path, family: str, params: FeetParams) -> _CleanupTake:
    """Read and check a clean take for :func:`cleanup_trials`."""
    known = family in CM_FAMILIES or path.name in CM_TAKES
    motion = read_bvh(path, length_unit="cm") if known else read_bvh(path)
    points, skipped = motion_foot_points(motion)
    scale = 1.0 if known else ASSUMED_HEIGHT_CM / points.body_height
    clean = check_feet(points, params)
    rig = foot_rig(motion)
    legs = leg_subtree(motion.skeleton, rig.legs[0].hip) | leg_subtree(
        motion.skeleton, rig.legs[1].hip
    )
    return _CleanupTake(
        path, family, params, motion, points, skipped, scale, clean, rig, legs,
        hip_knee=[j for leg in rig.legs for j in (leg.hip, leg.knee)],
        blend=max(1, round(BLEND_S * motion.fps)),
        flat_axes=list(horizontal_axes(clean.up.axis)),
        plant=params.plant_speed * points.leg_length,
    )  # fmt: skip


def cleanup_trials(
    path: Path,
    family: str,
    params: FeetParams,
    seed: int,
    slides_cm: Sequence[float] = CLEANUP_SLIDES_CM,
) -> list[CleanupTrial]:
    """Inject each slide into each contact (longer than 0.15 s) of a clean take through the
    leg (:func:`mocapqa.feet.inject.leg_slide_offsets`, over the contact's middle as
    :func:`run_trials` does, held to the contact's end and eased out after it), run the check
    on the result and lock every contact it finds (``--apply all``); measure what is left
    of the slide and what else changed (:class:`CleanupTrial`)."""
    take = _cleanup_take(path, family, params)
    rng = np.random.default_rng([seed, sum(path.name.encode())])
    trials = []
    for contact in take.clean.contacts:
        if (contact.end - contact.start + 1) / take.points.fps < MIN_CONTACT_S:
            continue
        start, end = contact.start + take.skipped, contact.end + take.skipped
        clean_cm = _travel_cm(
            take.motion, take.clean.up, params, contact.foot, start, end, take.scale
        )
        for size in slides_cm:
            angle = rng.uniform(0.0, 2.0 * np.pi)
            trials.append(_slide_trial(take, contact, size, angle, clean_cm))
    return trials


def _slide_trial(
    take: _CleanupTake, contact: Contact, size: float, angle: float, clean_cm: float
) -> CleanupTrial:
    """One slide of ``size`` cm in direction ``angle`` (radians, in the floor plane) injected
    through the leg into ``contact``, then every contact the check finds locked."""
    motion, params, skipped, scale = take.motion, take.params, take.skipped, take.scale
    start, end = contact.start + skipped, contact.end + skipped
    foot = SIDES.index(contact.foot)
    middle = (start + end) // 2
    reach = min((end - start) // 2, int(params.skate_window_s * take.points.fps / 2))
    displacement = np.zeros(3)
    displacement[take.flat_axes] = (size / scale) * np.array([np.cos(angle), np.sin(angle)])
    offsets, changed = leg_slide_offsets(
        motion.n_frames, foot, middle - reach, middle + reach, end, displacement, take.blend
    )
    injected, _ = shift_ankles(motion, take.rig, offsets, changed)
    in_points, _ = motion_foot_points(injected)
    report = check_feet(in_points, params, take.clean.up)
    locks = [Lock(c.foot, c.start + skipped, c.end + skipped) for c in report.contacts]
    depths = sole_heights(
        report.elevations, report.floor.point_offsets, in_points.sides,
        params.sole_depth * in_points.leg_length, skipped, motion.n_frames,
    ) if params.sole_pivot else None  # fmt: skip
    pops, result, cpu, before, after = _lock_anchors(take, injected, locks, depths)
    inside = np.zeros((motion.n_frames, 2), dtype=bool)
    for lock in locks:
        inside[lock.start : lock.end + 1, SIDES.index(lock.foot)] = True
    hip_knee = take.hip_knee
    angles = np.rad2deg(
        geodesic_angle(injected.quats[:, hip_knee], result.motion.quats[:, hip_knee])
    ).reshape(motion.n_frames, 2, 2)  # (F, leg, hip/knee)
    per_leg = angles.max(axis=-1)
    blends = result.changed & ~inside
    untouched = ~result.changed & ~inside
    legs = take.legs
    up = take.clean.up
    return CleanupTrial(
        take.path.name, take.family, contact.foot, size, clean_cm,
        _travel_cm(injected, up, params, contact.foot, start, end, scale),
        _travel_cm(result.motion, up, params, contact.foot, start, end, scale),
        _travel_cm(result.motion, up, dataclasses.replace(params, sole_pivot=False),
                   contact.foot, start, end, scale),
        float(per_leg[blends].max(initial=0.0)),
        float(per_leg[untouched].max(initial=0.0)),
        int(np.sum(np.any(after[:, ~legs] != before[:, ~legs], axis=(0, 2)))),
        pops, int(result.clamped.sum()), int(result.changed.sum()), cpu,
    )  # fmt: skip


def _lock_anchors(
    take: _CleanupTake, injected: Motion, locks: list[Lock], depths: FloatArray | None
) -> tuple[dict[str, float], LockResult, float, FloatArray, FloatArray]:
    """Lock ``injected`` with each anchor ("start", then "middle"): per anchor the largest
    speed the lock adds to an ankle, cm/s; and of the last, the result, its CPU seconds and
    the world joint positions before and after, shape (F, J, 3)."""
    rig, scale = take.rig, take.scale
    ankles = [leg.ankle for leg in rig.legs]
    pops = {}
    for anchor in ("start", "middle"):
        began = time.process_time()
        result = lock_feet(
            injected,
            rig,
            take.clean.up,
            locks,
            take.plant,
            take.points.leg_length,
            anchor,
            first=take.skipped,
            depths=depths,
        )
        cpu = time.process_time() - began
        before = forward_kinematics(injected)[1]
        after = forward_kinematics(result.motion)[1]
        moved = after[:, ankles] - before[:, ankles]
        added = np.linalg.norm(np.diff(moved, axis=0), axis=-1) * injected.fps * scale
        pops[anchor] = float(added.max()) if added.size else 0.0
    return pops, result, cpu, before, after


def held_back_cleanup(
    corpus_dir: Path, takes: Sequence[BenchTake], params: FeetParams, seed: int
) -> list[CleanupTrial]:
    """:func:`cleanup_trials` on every held-back take of ``takes`` (the bench's split)."""
    held = {t.name: t.family for t in takes if t.held_back}
    trials: list[CleanupTrial] = []
    for path in corpus_files(corpus_dir):
        if path.name in held:
            trials += cleanup_trials(path, held[path.name], params, seed)
    return trials
