"""Foot locking: hold a planted foot where it stands, by a two-bone leg IK on BVH takes
(:func:`lock_feet`), and the one place that chooses the contacts to lock and applies them to
any take (:func:`fix_feet`: BVH by the IK, keypoint and C3D marker takes pinned,
:mod:`mocapqa.feet.pin`).

Conventions
-----------
* The offsets come from :mod:`mocapqa.feet.lock` (the pivot, its planted slide, the blends);
  frames are the motion's, a leading bind pose (``first``) is never moved.
* **Only the legs.** The ankle goes to its target by :func:`mocapqa.feet.ik.solve_leg`, which
  changes the local rotations of the hip, the knee and the ankle (the foot keeps its world
  orientation); translations and every other rotation are the input's, so every joint outside
  the hips' subtrees keeps its world position exactly, and frames outside the locked contacts
  and their blends keep every rotation bit for bit.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles
from mocapqa.errors import InputError
from mocapqa.feet.check import FeetReport
from mocapqa.feet.contacts import Contact
from mocapqa.feet.fix_choice import choose_locks
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.ik import Leg, solve_leg
from mocapqa.feet.lock import (
    BLEND_S,
    Anchor,
    Lock,
    lock_offsets,
    pivot_steps,
    planted_travel,
    sole_heights,
)
from mocapqa.feet.params import FeetParams
from mocapqa.feet.pin import foot_keypoints, marker_foot_members, pin_feet
from mocapqa.feet.points import SIDES, FootPoints
from mocapqa.feet.tracks import horizontal_axes
from mocapqa.kinematics.forward import forward_kinematics

__all__ = [
    "PASSES",
    "REACH_TOLERANCE",
    "FootFix",
    "FootRig",
    "LockResult",
    "fix_feet",
    "foot_rig",
    "lock_feet",
    "shift_ankles",
]

PASSES = 2
"""Solves of a BVH lock: the second solves again for the slide the first left by the lock's own
measure (the IK moves the sole under a rolling foot a little as it moves the ankle). Chosen on
the fit takes of the cleanup bench (docs/feet.md "Figures"): 2 passes held 66.0 % of the
trials at 0.5 cm or less against 62.0 % for 1, 3 passes 67.1 %."""
REACH_TOLERANCE = 0.001
"""A frame counts as clamped when its ankle ends farther than this from its target, leg lengths
(0.9 mm at a 90 cm leg): a leg straight at heel strike misses a target beyond it by a hair."""


@dataclass(frozen=True, slots=True)
class FootRig:
    """The joints a foot lock reads and moves, per side (left, right).

    Parameters
    ----------
    legs : tuple of Leg
        Hip, knee and ankle of the left and the right leg.
    points : tuple of tuple of int
        Per side, the foot points whose pivot is held: the ankle, then the toe joint when the
        rig has one.
    """

    legs: tuple[Leg, Leg]
    points: tuple[tuple[int, ...], tuple[int, ...]]


@dataclass(frozen=True, slots=True)
class LockResult:
    """A locked take and what the lock did.

    Parameters
    ----------
    motion : Motion
        The take with the locks applied.
    changed : ndarray of bool, shape (F, 2)
        Frames whose left and right leg were solved (contacts and their blends).
    clamped : ndarray of int, shape (L,)
        Per contact measured, frames of the contact and its blends whose target was out of
        reach by more than :data:`REACH_TOLERANCE` leg lengths.
    miss : ndarray, shape (L,)
        Per contact measured, the largest distance by which the ankle fell short of its
        target, take units.
    before, after : ndarray, shape (L,)
        Per contact measured, the pivot's planted travel over the contact
        (:func:`mocapqa.feet.lock.planted_travel`) in the input and in the result, take units.
    """

    motion: Motion
    changed: BoolArray
    clamped: np.ndarray
    miss: FloatArray
    before: FloatArray
    after: FloatArray


def foot_rig(motion: Motion, mapping: dict[str, str] | None = None) -> FootRig:
    """The legs and foot points of a BVH take's rig (:func:`mocapqa.core.rig.find_roles`).

    Raises
    ------
    InputError
        If a side has no upper leg, lower leg or foot joint.
    """
    rig = find_roles(motion.skeleton, mapping)
    legs, points = [], []
    for side in SIDES:
        hip, knee, ankle = (rig.joint(side, r) for r in ("upper_leg", "lower_leg", "foot"))
        if hip is None or knee is None or ankle is None:
            raise InputError(
                f"Expected upper leg, lower leg and foot joints on the {side} side, got "
                f"{hip}, {knee}, {ankle} (name them with --mapping FILE, see docs/rigs.md)"
            )
        toe = rig.joint(side, "toe")
        legs.append(Leg(hip, knee, ankle))
        points.append((ankle,) if toe is None else (ankle, toe))
    return FootRig((legs[0], legs[1]), (points[0], points[1]))


def shift_ankles(
    motion: Motion,
    rig: FootRig,
    offsets: FloatArray,
    changed: BoolArray,
    world: tuple[FloatArray, FloatArray] | None = None,
) -> tuple[Motion, FloatArray]:
    """Move each ankle by ``offsets`` on the ``changed`` frames with the leg IK.

    Parameters
    ----------
    motion : Motion
    rig : FootRig
    offsets : ndarray, shape (F, 2, 3)
        Per frame and foot, take units.
    changed : ndarray of bool, shape (F, 2)
        Frames to solve per foot; the others keep their rotations bit for bit.
    world : tuple of ndarray, optional
        ``forward_kinematics(motion)``, when the caller has it.

    Returns
    -------
    motion : Motion
    miss : ndarray, shape (F, 2)
        Distance from each solved ankle to its target (0 within reach), take units.
    """
    world_quats, world_positions = world if world is not None else forward_kinematics(motion)
    quats = motion.quats.copy()
    miss = np.zeros(changed.shape)
    for foot, leg in enumerate(rig.legs):
        frames = np.flatnonzero(changed[:, foot])
        if frames.size == 0:
            continue
        targets = world_positions[frames, leg.ankle] + offsets[frames, foot]
        solved, out = solve_leg(
            motion.skeleton, leg, quats[frames], world_quats[frames],
            world_positions[frames], targets,
        )  # fmt: skip
        quats[frames] = solved
        miss[frames, foot] = out
    moved = Motion(motion.skeleton, quats, motion.translations, motion.fps, motion.euler_hint_deg)
    return moved, miss


def _window_counts(
    clamped: BoolArray, miss: FloatArray, contacts: Sequence[Lock], blend: int
) -> tuple[IntArray, FloatArray]:
    """Per contact, clamped frames and the largest miss over the contact and its blends."""
    if not contacts:
        return np.zeros(0, dtype=np.intp), np.zeros(0)
    n_frames = clamped.shape[0]
    feet = np.array([SIDES.index(k.foot) for k in contacts], dtype=np.intp)
    lo = np.array([max(k.start - blend, 0) for k in contacts], dtype=np.intp)
    hi = np.array([min(k.end + blend + 1, n_frames) for k in contacts], dtype=np.intp)
    counts = np.concatenate([np.zeros((1, 2), dtype=np.intp), np.cumsum(clamped, axis=0)])
    n_clamped: IntArray = counts[hi, feet] - counts[lo, feet]
    spans = hi - lo
    rows = (
        np.repeat(lo, spans)
        + np.arange(int(spans.sum()))
        - np.repeat(np.cumsum(spans) - spans, spans)
    )
    largest: FloatArray = np.maximum.reduceat(miss[rows, np.repeat(feet, spans)],
                                              np.cumsum(spans) - spans)  # fmt: skip
    return n_clamped, largest


def lock_feet(
    motion: Motion,
    rig: FootRig,
    up: UpAxis,
    locks: Sequence[Lock],
    plant_speed: float,
    leg_length: float,
    anchor: Anchor = "middle",
    blend_s: float = BLEND_S,
    first: int = 0,
    measure: Sequence[Lock] | None = None,
    depths: FloatArray | None = None,
) -> LockResult:
    """Lock the feet of a BVH take during the given contacts: the ankles moved by the offsets
    that hold each pivot (:func:`mocapqa.feet.lock.lock_offsets`), solved :data:`PASSES` times,
    each pass on the slide the previous one left.

    Parameters
    ----------
    motion : Motion
    rig : FootRig
    up : UpAxis
        The take's up axis (the feet check's).
    locks : sequence of Lock
        Contacts to lock, motion frames.
    plant_speed : float
        Take units per second (:func:`mocapqa.feet.lock.planted_tracks`; the feet check's
        ``plant_speed`` times the leg length).
    leg_length : float
        Take units (:data:`REACH_TOLERANCE`).
    anchor : {"middle", "start"}
    blend_s : float
        Seconds of blend on either side of each contact.
    first : int
        Leading frames (a bind pose) never moved.
    measure : sequence of Lock, optional
        The contacts whose slide and clamped frames are reported (``locks`` when None).
    depths : ndarray, shape (F, P), optional
        Each foot point's height above the sole (:func:`mocapqa.feet.lock.sole_heights`, the
        points of ``rig.points``, left then right), take units: the lock then holds the sole
        under the pivot, what the skate check reads. The IK keeps each foot's world
        orientation and its ankle's height, so the heights hold for the result too. None holds
        the joints.

    Returns
    -------
    LockResult
        ``clamped``, ``before`` and ``after`` per contact of ``measure``.
    """
    world = forward_kinematics(motion)
    joints = [j for group in rig.points for j in group]
    columns = np.cumsum([0, len(rig.points[0])])
    local = [list(range(c, c + len(g))) for c, g in zip(columns, rig.points, strict=True)]
    steps = pivot_steps(world[1][:, joints], local, up, depths)
    flat, weights = lock_offsets(steps, locks, motion.fps, plant_speed, anchor, blend_s, first)
    offsets = np.zeros((motion.n_frames, 2, 3))
    offsets[..., list(horizontal_axes(up.axis))] = flat
    changed = weights > 0
    fixed, miss = shift_ankles(motion, rig, offsets, changed, world)
    after_world = forward_kinematics(fixed)
    after = pivot_steps(after_world[1][:, joints], local, up, depths)
    for _ in range(PASSES - 1):
        flat, _ = lock_offsets(after, locks, motion.fps, plant_speed, anchor, blend_s, first)
        offsets[..., list(horizontal_axes(up.axis))] = flat
        fixed, miss = shift_ankles(fixed, rig, offsets, changed, after_world)
        after_world = forward_kinematics(fixed)
        after = pivot_steps(after_world[1][:, joints], local, up, depths)
    clamped = miss > REACH_TOLERANCE * leg_length
    blend = max(1, round(blend_s * motion.fps))
    measured = locks if measure is None else measure
    n_clamped, misses = _window_counts(clamped, miss, measured, blend)
    fps = motion.fps
    before_travel = planted_travel(steps, measured, fps, plant_speed)
    after_travel = planted_travel(after, measured, fps, plant_speed)
    return LockResult(fixed, changed, n_clamped, misses, before_travel, after_travel)


@dataclass(frozen=True, slots=True)
class FootFix:
    """A take with its chosen contacts locked, and what the locks did.

    Parameters
    ----------
    take : Motion or KeypointSequence
        The locked take (a BVH motion, or keypoints / markers).
    chosen : list of Contact
        The contacts locked, the check's frames.
    before, after : ndarray, shape (C,)
        Per contact of the check, the pivot's planted travel in the input and the result
        (:func:`mocapqa.feet.lock.planted_travel`), take units.
    clamped : ndarray of int, shape (C,)
        Per contact of the check, frames out of the leg's reach (0 for pinned takes).
    miss : ndarray, shape (C,)
        Per contact of the check, the largest distance by which the ankle fell short of its
        target (0 for pinned takes), take units.
    """

    take: Motion | KeypointSequence
    chosen: list[Contact]
    before: FloatArray
    after: FloatArray
    clamped: IntArray
    miss: FloatArray


def fix_feet(
    checked: Motion | KeypointSequence,
    points: FootPoints,
    report: FeetReport,
    skipped: int,
    apply: str,
    params: FeetParams,
    target: Motion | KeypointSequence | None = None,
    mapping: dict[str, str] | None = None,
) -> FootFix:
    """Choose the contacts ``apply`` names (:func:`mocapqa.feet.fix_choice.choose_locks`) and
    lock them: what ``mocapqa feet fix`` and the reviewed download both do.

    A BVH take's legs are solved by :func:`lock_feet`; a keypoint take's foot keypoints
    (:func:`mocapqa.feet.pin.foot_keypoints`) and a C3D take's foot markers
    (:func:`mocapqa.feet.pin.marker_foot_members`) are pinned by
    :func:`mocapqa.feet.pin.pin_feet`. When the check reads the sole (``params.sole_pivot``)
    the locks hold the sole under the pivot (:func:`mocapqa.feet.lock.sole_heights`).

    Parameters
    ----------
    checked : Motion or KeypointSequence
        The take the feet check read.
    points, report, skipped
        Its feet check (:func:`mocapqa.pipeline.feet.check_take_feet`).
    apply : str
        ``confident``, ``all``, ``none`` or ids (:func:`mocapqa.feet.fix_choice.choose_locks`).
    params : FeetParams
        The check's thresholds (``plant_speed``, ``sole_depth``, ``sole_pivot``).
    target : Motion or KeypointSequence, optional
        The take to lock, of the same kind, rig and frames as ``checked`` (a reviewed take with
        its other corrections); ``checked`` when None.
    mapping : dict, optional
        Role key → joint name (BVH).

    Returns
    -------
    FootFix

    Raises
    ------
    InputError
        For ``apply`` ids the check does not know, or a rig without legs.
    """
    chosen = choose_locks(apply, report.contacts, report.findings, skipped)
    take = checked if target is None else target
    locks = [Lock(c.foot, c.start + skipped, c.end + skipped) for c in chosen]
    measure = [Lock(c.foot, c.start + skipped, c.end + skipped) for c in report.contacts]
    leg = points.leg_length
    plant_speed = params.plant_speed * leg
    depths = sole_heights(
        report.elevations, report.floor.point_offsets, points.sides, params.sole_depth * leg,
        skipped, take.n_frames,
    ) if params.sole_pivot else None  # fmt: skip
    if isinstance(take, Motion):
        locked = lock_feet(
            take, foot_rig(take, mapping), report.up, locks, plant_speed, leg, first=skipped,
            measure=measure, depths=depths,
        )  # fmt: skip
        return FootFix(locked.motion, chosen, locked.before, locked.after,
                       np.asarray(locked.clamped, dtype=np.intp), locked.miss)  # fmt: skip
    if take.source_format == "c3d":
        own, members = marker_foot_members(take.names, points)
    else:
        own, members = foot_keypoints(take.names, points.names, points.sides)
    pinned = pin_feet(
        take.positions, own, members, report.up, locks, take.fps, plant_speed,
        measure=measure, depths=depths,
    )  # fmt: skip
    moved = dataclasses.replace(take, positions=pinned.positions)
    zeros = np.zeros(len(measure))
    return FootFix(moved, chosen, pinned.before, pinned.after, zeros.astype(np.intp), zeros)
