"""A canonical (anatomical) frame per role joint, so limits mean the same on every rig.

Every rig bakes its own joint orientations into its rotations: Character Creator bones run
along local +Y with the legs resting at a 180° swing, Bandai bones along ±X, CMU along the
world axes of a T-pose. The same anatomical motion therefore gives different local rotations
on each rig. This module finds, for each role joint ``j``, a constant rotation ``C_j`` from an
anatomical frame to the joint's local frame, so that ``A_j = R_j C_j`` (``R_j`` the joint's
world rotation) is the segment's anatomical frame:

* ``y`` — the long axis, from the joint to the next role joint down the limb (upper arm →
  forearm, ..., foot → toe); a foot without a toe points to the mean of its children's
  OFFSETs and End Sites; a hand, on every rig, continues its parent's bone as seen from its
  own frame on average over the frames (its mean pose is a straight wrist), because CMU and
  Bandai hands have no knuckle offsets to point at and pointing at them where they exist
  read one rig's wrists 10–14° flexed against the others;
* ``x`` — the flexion axis, the normal of the limb plane: ``y × u`` with ``u`` the neighbouring
  segment (upper arm and upper leg: the forearm / lower leg; forearm, lower leg and foot: their
  parent segment; clavicle: the body's up axis); a hand, whose wrist hardly bends, takes the
  forearm frame's ``x`` instead. Its direction about ``y`` in the joint's frame is the weighted
  circular median over the frames (weights sin² of the bend, so straight frames weigh nothing
  and a burst of twist errors in under half the weight cannot move it), signed to the body's
  left (forward for the clavicle); when the limb hardly bends (mean sin² under sin² 10°), the
  body's left axis is used;
* ``z = x × y``.

The body's left axis is the right→left hip vector (shoulders for the arms), the up axis runs
from the hips' midpoint to the shoulders' midpoint. The parent frame of a clavicle or an upper
leg is the body frame in its skeleton parent's frame: ``x`` left, ``y`` up (down for the legs,
so that standing is near the identity), ``z = x × y``.
The canonical local rotation of a role joint is ``Q_j = conj(A_parent) ⊗ A_j``, with the
parent the previous role joint of the limb, so helper joints between them (twist bones, CMU's
``LHipJoint``) do not matter.

**Reference pose.** The frames come from the takes' own frames (world geometry), not from
the OFFSET rest pose, which holds no anatomy on Character Creator and Bandai (docs/limits.md).
Re-expressing a rig with rotated joint frames (same world poses) gives identical ``Q_j``.

A take's own frames follow it when most of its frames are damaged, so a model stores the frames
of every rig it was built from, estimated over all that rig's takes (:func:`rig_frames`, looked
up by :func:`rig_key`); only a rig the model has not seen is framed from the take checked.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion, Skeleton
from mocapqa.core.rig import SIDES, RigMap, Side, find_roles, mapped_roles, role_key
from mocapqa.errors import InputError
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import conjugate, rotate
from mocapqa.limits.rig import MODELLED_ROLES, axis_label

__all__ = [
    "CANONICAL_AXIS",
    "STAND_IN_PARENTS",
    "CanonicalFrames",
    "canonical_frames",
    "frame_needs",
    "pose_sample",
    "rig_frames",
    "rig_key",
    "role_parent",
    "stand_in_roles",
    "take_frames",
    "without_stand_ins",
]

# The long axis of every canonical frame.
CANONICAL_AXIS = np.array([0.0, 1.0, 0.0])
_FLEXION_AXIS = np.array([1.0, 0.0, 0.0])

_PARENT_ROLE = {
    "upper_arm": "clavicle",
    "forearm": "upper_arm",
    "hand": "forearm",
    "lower_leg": "upper_leg",
    "foot": "lower_leg",
}
# Roles whose limb plane gives a proximal segment's flexion axis.
_PLANE_ROLE = {"upper_arm": "forearm", "upper_leg": "lower_leg"}


STAND_IN_PARENTS = {"upper_arm": "clavicle"}
"""Roles checked without their parent role: the missing parent is taken at the model's mean
pose relative to the body (a clavicle moves little against the chest; rigs such as Human3.6M's
have none)."""


def stand_in_roles(roles: Sequence[str]) -> tuple[str, ...]:
    """The role keys among ``roles`` whose parent role is missing from them and stood in for
    (:data:`STAND_IN_PARENTS`): an upper arm without its side's clavicle."""
    present = set(roles)
    out = []
    for key in roles:
        side, _, role = key.partition("_")
        parent = STAND_IN_PARENTS.get(role)
        if parent is not None and f"{side}_{parent}" not in present:
            out.append(key)
    return tuple(out)


def frame_needs(role: str) -> tuple[str, ...]:
    """The roles a role's canonical frame is measured with: its parent role (else the rotation
    would be read against the body frame, which the model's role was not; except a parent in
    :data:`STAND_IN_PARENTS`) and, for an upper arm or upper leg, the next segment that gives
    its flexion axis. Without them the role is not checked (a hand read against the body, not
    the forearm, reads as 100° out)."""
    parent = _PARENT_ROLE.get(role)
    if STAND_IN_PARENTS.get(role) == parent:
        parent = None
    return tuple(r for r in (parent, _PLANE_ROLE.get(role)) if r is not None)


_DISTAL_ROLE = {
    "clavicle": "upper_arm",
    "upper_arm": "forearm",
    "forearm": "hand",
    "upper_leg": "lower_leg",
    "lower_leg": "foot",
    "foot": "toe",
}
_MIN_BEND_SIN2 = float(np.sin(np.deg2rad(10.0)) ** 2)
_MEDIAN_FRAMES = 4000
_ARM_ROLES = ("clavicle", "upper_arm", "forearm", "hand")


def pose_sample(n_frames: int) -> np.ndarray | None:
    """Frames a frame estimate uses out of ``n_frames``: at most 4,000 evenly spaced (the
    medians are as stable and the cost stays bounded), or None for all of them."""
    if n_frames <= _MEDIAN_FRAMES:
        return None
    return np.linspace(0, n_frames - 1, _MEDIAN_FRAMES).astype(np.intp)


def role_parent(role: str) -> str | None:
    """The role whose anatomical frame a role's rotation is taken relative to (None: body)."""
    return _PARENT_ROLE.get(role)


@dataclass(frozen=True, slots=True)
class CanonicalFrames:
    """Canonical frames of one take's role joints.

    Parameters
    ----------
    roles : tuple of str
        Role keys found, in :data:`MODELLED_ROLES` order, left side first.
    joints : ndarray of int, shape (R,)
        Joint index per role.
    parents : ndarray of int, shape (R,)
        Joint index whose frame each role is relative to (the parent role's joint, or the
        skeleton parent for a clavicle / upper leg).
    frames : ndarray, shape (R, 4)
        ``C_j``: anatomical → local joint frame, unit quaternions (scalar-last).
    parent_frames : ndarray, shape (R, 4)
        The same for the parents (the body frame for a clavicle / upper leg).
    not_checked : tuple of str
        Modelled role keys absent from the skeleton, or whose frame needs one that is
        (:func:`frame_needs`).
    stand_ins : tuple of str
        Role keys whose parent role is missing but may be stood in for (an upper arm without
        a clavicle, :data:`STAND_IN_PARENTS`): their parent frame is the body frame in the
        skeleton parent, which a check turns by the model's mean pose of the missing role.
    """

    roles: tuple[str, ...]
    joints: np.ndarray
    parents: np.ndarray
    frames: FloatArray
    parent_frames: FloatArray
    not_checked: tuple[str, ...]
    stand_ins: tuple[str, ...] = ()


def _unit(v: FloatArray) -> FloatArray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.asarray(v / np.where(n > 1e-12, n, 1.0), dtype=np.float64)


def _local(world_quats: FloatArray, vectors: FloatArray) -> FloatArray:
    """World vectors ``(F, 3)`` in a joint's frame (``R^T v``), shape (F, 3)."""
    return rotate(conjugate(world_quats), vectors)


def _parallel(x: FloatArray, y: FloatArray) -> bool:
    """Whether two directions are (nearly) parallel, or one has no length: no frame has them
    as its ``x`` and ``y``."""
    return bool(np.linalg.norm(np.cross(_unit(x), _unit(y))) < 1e-6)


def _frame_quat(x: FloatArray, y: FloatArray) -> FloatArray:
    """Quaternion of the frame with columns ``(x⊥, y, x⊥ × y)``, ``y`` taken exactly."""
    y = _unit(y)
    x = _unit(x - np.dot(x, y) * y)
    matrix = np.stack((x, y, np.cross(x, y)), axis=1)
    return np.asarray(Rotation.from_matrix(matrix).as_quat(), dtype=np.float64)


def _median_direction(
    vectors: FloatArray, axis: FloatArray, sign_ref: FloatArray, ignore: BoolArray | None = None
) -> tuple[FloatArray, float]:
    """Robust direction of ``vectors`` ``(F, 3)`` around ``axis``, and their mean squared norm.

    The weighted circular median (weights = squared norms, so straight limbs weigh nothing)
    of the vectors' azimuths about ``axis``, on a 1° grid: up to half the frames may point
    anywhere (a burst of twist errors) without moving it. Frames flagged in ``ignore`` (F,)
    weigh nothing, unless that leaves no weight at all. Signed like ``sign_ref``.
    """
    e1 = _unit(sign_ref - np.dot(sign_ref, axis) * axis)
    if np.linalg.norm(e1) < 0.5:
        e1 = _unit(np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0]))
    e2 = np.cross(axis, e1)
    weights = np.sum(vectors * vectors, axis=-1)
    if ignore is not None and (weights * ~ignore).sum() > 0:
        weights = weights * ~ignore
    azimuth = np.arctan2(vectors @ e2, vectors @ e1)
    best = 0.0
    # Coarse to fine: 10° steps round the circle, then 1° steps around the best.
    for grid in (np.deg2rad(np.arange(-180.0, 180.0, 10.0)), np.deg2rad(np.arange(-10.0, 11.0))):
        candidates = best + grid
        cost = np.abs((azimuth[None, :] - candidates[:, None] + np.pi) % (2 * np.pi) - np.pi)
        best = float(candidates[int(np.argmin(cost @ weights))])
    direction = np.cos(best) * e1 + np.sin(best) * e2
    if np.dot(direction, sign_ref) < 0:
        direction = -direction
    return np.asarray(direction, dtype=np.float64), float(np.mean(weights))


def _end_axis(skeleton: Skeleton, joint: int) -> FloatArray | None:
    """Long axis of a segment without a next role joint (a foot without a toe): toward the
    mean of its children and End Sites; None when they all sit at zero offset.

    A sum, not the longest child, so two children of equal length cannot swap places.
    """
    offsets = [skeleton.offsets[c] for c in skeleton.children(joint)]
    offsets += [np.asarray(o, dtype=np.float64) for o in skeleton.end_site_offsets(joint)]
    total = np.sum(offsets, axis=0) if offsets else np.zeros(3)
    if np.linalg.norm(total) > 1e-4:
        return _unit(np.asarray(total, dtype=np.float64))
    return None


def _body_axes(rig: RigMap, positions: FloatArray, arms: bool) -> tuple[FloatArray, FloatArray]:
    """Per-frame body left and up axes ``(F, 3)`` from the hips and shoulders."""
    pairs = (
        [("upper_arm", "clavicle"), ("upper_leg",)]
        if arms
        else [("upper_leg",), ("upper_arm", "clavicle")]
    )
    left = None
    for group in pairs:
        for role in group:
            jl, jr = rig.joint("left", role), rig.joint("right", role)
            if jl is not None and jr is not None:
                left = positions[:, jl] - positions[:, jr]
                break
        if left is not None:
            break
    mids = []
    for group in (("upper_leg",), ("upper_arm", "clavicle")):
        for role in group:
            jl, jr = rig.joint("left", role), rig.joint("right", role)
            if jl is not None and jr is not None:
                mids.append(0.5 * (positions[:, jl] + positions[:, jr]))
                break
    if left is None or len(mids) != 2:
        raise InputError(
            "Expected both hips and both shoulders (or clavicles) among the roles to find the "
            f"body's axes, got roles {sorted(rig.roles)}"
        )
    return _unit(left), _unit(mids[1] - mids[0])


def canonical_frames(
    motion: Motion | Skeleton,
    rig: RigMap | None = None,
    world: tuple[FloatArray, FloatArray] | None = None,
    ignore: BoolArray | None = None,
) -> CanonicalFrames:
    """Canonical frame of every modelled role joint of a take.

    Parameters
    ----------
    motion : Motion or Skeleton
        Any rig whose roles are found by :func:`mocapqa.core.rig.find_roles`; a skeleton
        alone when ``world`` is given.
    rig : RigMap, optional
        Roles to use instead of the automatic ones.
    world : (ndarray, ndarray), optional
        The take's world rotations ``(F, J, 4)`` and positions ``(F, J, 3)``, when computed;
        only the frames :func:`pose_sample` keeps are used.
    ignore : ndarray of bool, shape (F, J), optional
        Frames of each joint that must not set its flexion axis: those inside twist intervals
        found on the take, whose roll about the bone is off by the interval's level (a hand
        also ignores its forearm's). Unflagged frames alone decide, when there are any.

    Returns
    -------
    CanonicalFrames

    Raises
    ------
    InputError
        If the skeleton has no modelled role, or lacks the hips and shoulders that give the
        body's axes.
    """
    skeleton = motion if isinstance(motion, Skeleton) else motion.skeleton
    rig = find_roles(skeleton) if rig is None else rig
    # Each modelled role joint by (side, role), with the roles its frame needs: the index is
    # kept with the key, so no later look-up can come back empty.
    keys: dict[tuple[Side, str], int] = {}
    for s in SIDES:
        for r in MODELLED_ROLES:
            j = rig.joint(s, r)
            if j is not None and all(rig.joint(s, n) is not None for n in frame_needs(r)):
                keys[(s, r)] = j
    if not keys:
        raise InputError(
            f"Expected a skeleton with limb roles, got none among {skeleton.names[:8]}"
        )
    if world is None:
        if isinstance(motion, Skeleton):
            raise InputError("Expected a take's world poses with a skeleton alone, got none")
        world = forward_kinematics(motion)
    quats, positions = world
    keep = pose_sample(quats.shape[0])
    if keep is not None:
        quats, positions = quats[keep], positions[keep]
        ignore = None if ignore is None else ignore[keep]
    body = {arms: _body_axes(rig, positions, arms) for arms in (True, False)}
    roles, joints, parents, frames, parent_frames = [], [], [], [], []
    cache: dict[int, FloatArray] = {}
    long_axes: dict[int, FloatArray] = {}

    def mean_direction(joint: int, vectors: FloatArray) -> FloatArray | None:
        """The mean direction of world vectors ``(F, 3)`` seen from the joint's frame; None
        when they are all (nearly) zero, a bone of no length."""
        if np.median(np.linalg.norm(vectors, axis=-1)) < 1e-6:
            return None
        mean = np.mean(_unit(_local(quats[:, joint], vectors)), axis=0)
        return _unit(mean) if np.linalg.norm(mean) > 1e-6 else None

    def long_axis(side: str, role: str, joint: int) -> FloatArray:
        distal = rig.joint(side, _DISTAL_ROLE[role]) if role in _DISTAL_ROLE else None  # type: ignore[arg-type]
        if distal is not None:
            axis = mean_direction(joint, positions[:, distal] - positions[:, joint])
        elif role == "hand":
            # A hand continues its forearm's bone (from the forearm joint, so that a helper
            # bone of no length between them does not matter), seen from its own frame, on
            # average over the frames: CMU and Bandai hands have no knuckle offsets, and
            # pointing the others at theirs read the Character Creator wrist 10-14 degrees
            # flexed against those rigs. The knuckles only stand in for a hand at its forearm.
            forearm = rig.joint(side, "forearm")  # type: ignore[arg-type]
            anchor = int(skeleton.parents[joint]) if forearm is None else forearm
            axis = mean_direction(joint, positions[:, joint] - positions[:, anchor])
            if axis is None:
                axis = _end_axis(skeleton, joint)
        else:
            # A foot without a toe points to its End Site, or else continues its parent's bone.
            axis = _end_axis(skeleton, joint)
            if axis is None:
                parent = int(skeleton.parents[joint])
                axis = mean_direction(joint, positions[:, joint] - positions[:, parent])
        if axis is None:
            raise InputError(
                f"Expected the {side} {role.replace('_', ' ')} ({skeleton.names[joint]!r}) to "
                f"have a bone of non-zero length toward the next joint of its limb; its long "
                f"axis cannot be found (check the role mapping)"
            )
        return axis

    def world_long(side: str, role: str, joint: int) -> FloatArray:
        if joint not in long_axes:
            long_axes[joint] = long_axis(side, role, joint)
        return rotate(quats[:, joint], np.broadcast_to(long_axes[joint], (quats.shape[0], 3)))

    def frame_of(side: str, role: str, joint: int) -> FloatArray:
        if joint in cache:
            return cache[joint]
        left_w, up_w = body[role in _ARM_ROLES]
        along = world_long(side, role, joint)
        if role == "clavicle":
            partner = up_w
            sign_w = np.cross(left_w, up_w)
        elif role in ("upper_arm", "upper_leg"):
            child = rig.joint(side, _DISTAL_ROLE[role])  # type: ignore[arg-type]
            partner = world_long(side, _DISTAL_ROLE[role], child) if child is not None else left_w
            sign_w = left_w
        else:
            parent_role = _PARENT_ROLE[role]
            parent = rig.joint(side, parent_role)  # type: ignore[arg-type]
            partner = world_long(side, parent_role, parent) if parent is not None else left_w
            sign_w = left_w
        forearm = rig.joint(side, "forearm") if role == "hand" else None  # type: ignore[arg-type]
        skip = None if ignore is None else ignore[:, joint]
        if skip is not None and forearm is not None:
            skip = skip | ignore[:, forearm]  # type: ignore[index]
        kept = slice(None) if skip is None or skip.all() else ~skip
        sign_ref = np.mean(_local(quats[kept, joint], sign_w[kept]), axis=0)
        if forearm is not None:
            # The wrist hardly bends, so its bend plane is a weak, rig-dependent signal: the
            # hand takes the forearm's flexion axis, as seen from its own frame.
            forearm_x = rotate(frame_of(side, "forearm", forearm), _FLEXION_AXIS)
            normals = _local(quats[:, joint], rotate(quats[:, forearm], forearm_x[None]))
        else:
            normals = _local(quats[:, joint], np.cross(along, partner))
        flexion, bend = _median_direction(normals, long_axes[joint], sign_ref, skip)
        if bend < _MIN_BEND_SIN2 or _parallel(flexion, long_axes[joint]):
            flexion = sign_ref
        if _parallel(flexion, long_axes[joint]):
            # A segment along the body's left-right axis on average (a mapping that names an
            # arm joint for a leg role): no flexion axis can be found for it.
            raise InputError(
                f"Expected the {side} {role.replace('_', ' ')} ({skeleton.names[joint]!r}) to "
                "run across the body's left-right axis, got a segment along it; its flexion "
                "axis cannot be found (check the role mapping)"
            )
        cache[joint] = _frame_quat(flexion, long_axes[joint])
        return cache[joint]

    for (side, role), joint in keys.items():
        frames.append(frame_of(side, role, joint))
        parent_role = _PARENT_ROLE.get(role)
        parent = rig.joint(side, parent_role) if parent_role else None  # type: ignore[arg-type]
        if parent is not None and parent_role is not None:
            parent_frames.append(frame_of(side, parent_role, parent))
        else:
            parent = int(skeleton.parents[joint])
            if parent < 0:
                raise InputError(f"Expected role joint {skeleton.names[joint]!r} to have a parent")
            left_w, up_w = body[role in _ARM_ROLES]
            left_l = np.mean(_local(quats[:, parent], left_w), axis=0)
            up_l = np.mean(_local(quats[:, parent], up_w), axis=0)
            if _parallel(left_l, up_l):
                # Hips or shoulders stacked along the up axis (a mapping that names an arm
                # joint for a leg role): no body frame.
                raise InputError(
                    "Expected the body's left-right axis (hips, shoulders) across its up axis "
                    f"(hips to shoulders), got the two along each other, framing "
                    f"{skeleton.names[joint]!r} (check the role mapping)"
                )
            # Legs hang: their body frame's long axis points down, so standing is near identity.
            parent_frames.append(_frame_quat(left_l, up_l if role in _ARM_ROLES else -up_l))
        roles.append(role_key(side, role))
        joints.append(joint)
        parents.append(parent)
    missing = tuple(role_key(s, r) for s in SIDES for r in MODELLED_ROLES if (s, r) not in keys)
    return CanonicalFrames(
        roles=tuple(roles),
        joints=np.asarray(joints, dtype=np.intp),
        parents=np.asarray(parents, dtype=np.intp),
        frames=np.stack(frames),
        parent_frames=np.stack(parent_frames),
        not_checked=missing,
        stand_ins=stand_in_roles(roles),
    )


def without_stand_ins(frames: CanonicalFrames) -> CanonicalFrames:
    """``frames`` without the roles whose parent role is stood in for (listed as not
    checked instead)."""
    if not frames.stand_ins:
        return frames
    keep = [k for k, role in enumerate(frames.roles) if role not in frames.stand_ins]
    return CanonicalFrames(
        roles=tuple(frames.roles[k] for k in keep),
        joints=frames.joints[keep],
        parents=frames.parents[keep],
        frames=frames.frames[keep],
        parent_frames=frames.parent_frames[keep],
        not_checked=frames.not_checked + frames.stand_ins,
    )


def take_frames(
    motion: Motion,
    rig: RigMap | None = None,
    known: CanonicalFrames | None = None,
    ignore: BoolArray | None = None,
) -> CanonicalFrames:
    """``known`` (frames of the rig estimated over many takes, :func:`rig_frames`) if given,
    else the take's own frames, estimated from at most 4,000 evenly spaced frames, without the
    frames ``ignore`` (F, J) flags (see :func:`canonical_frames`)."""
    if known is not None:
        return known
    sample = motion
    keep = pose_sample(motion.n_frames)
    if keep is not None:
        sample = Motion(motion.skeleton, motion.quats[keep], motion.translations[keep], motion.fps)
        ignore = None if ignore is None else ignore[keep]
    return canonical_frames(sample, rig, ignore=ignore)


def rig_key(motion: Motion) -> str:
    """A key of a rig's joint conventions: joint names, parents, channels and OFFSET axes.

    The axis label of each OFFSET (``"+y"``, ``"-x"``, ...) stands for the joint frames: takes
    of one rig share it whatever the performer's proportions, while a rig re-expressed with
    rotated joint frames gets another key.
    """
    import hashlib

    skeleton = motion.skeleton
    digest = hashlib.sha256()
    for j, (name, parent, channels) in enumerate(
        zip(skeleton.names, skeleton.parents.tolist(), skeleton.channels, strict=True)
    ):
        offset = skeleton.offsets[j]
        label = axis_label(offset) if np.linalg.norm(offset) > 1e-4 else "0"
        digest.update(f"{name}|{parent}|{','.join(channels)}|{label};".encode())
    return digest.hexdigest()[:16]


def rig_frames(
    motions: Sequence[Motion], mapping: Mapping[str, str] | None = None
) -> CanonicalFrames:
    """Canonical frames of one rig estimated over several of its takes at once.

    The world poses of every take are pooled, so the medians of
    :func:`canonical_frames` run over all their frames: one short or damaged take cannot move
    them. Every take must have the same :func:`rig_key`. ``mapping`` (role key → joint name)
    sets roles where the rig has its joints (:func:`mocapqa.core.rig.mapped_roles`).

    Raises
    ------
    InputError
        If the takes are of different rigs (or none is given).
    """
    if not motions:
        raise InputError("Expected at least one take, got none")
    key = rig_key(motions[0])
    worlds = []
    for motion in motions:
        if rig_key(motion) != key:
            raise InputError("Expected takes of one rig (same joints and channels), got several")
        worlds.append(forward_kinematics(motion))
    pooled = (
        np.concatenate([w[0] for w in worlds]),
        np.concatenate([w[1] for w in worlds]),
    )
    rig = mapped_roles(motions[0].skeleton, mapping)
    return canonical_frames(motions[0], rig=rig, world=pooled)
