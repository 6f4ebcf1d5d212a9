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

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion, Skeleton
from mocapqa.core.rig import SIDES, RigMap, Side, find_roles, mapped_roles, role_key
from mocapqa.errors import InputError
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.limits.rig import MODELLED_ROLES, axis_label
from mocapqa.limits.segment_frames import PARENT_ROLE, SegmentFraming, body_axes

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
    parent = PARENT_ROLE.get(role)
    if STAND_IN_PARENTS.get(role) == parent:
        parent = None
    return tuple(r for r in (parent, _PLANE_ROLE.get(role)) if r is not None)


_MEDIAN_FRAMES = 4000


def pose_sample(n_frames: int) -> np.ndarray | None:
    """Frames a frame estimate uses out of ``n_frames``: at most 4,000 evenly spaced (the
    medians are as stable and the cost stays bounded), or None for all of them."""
    if n_frames <= _MEDIAN_FRAMES:
        return None
    return np.linspace(0, n_frames - 1, _MEDIAN_FRAMES).astype(np.intp)


def role_parent(role: str) -> str | None:
    """The role whose anatomical frame a role's rotation is taken relative to (None: body)."""
    return PARENT_ROLE.get(role)


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


def _framed_roles(skeleton: Skeleton, rig: RigMap) -> dict[tuple[Side, str], int]:
    """Each modelled role joint by (side, role) whose frame can be measured (the roles
    :func:`frame_needs` are present), the index kept with the key.

    Raises
    ------
    InputError
        If there is none.
    """
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
    return keys


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
    keys = _framed_roles(skeleton, rig)
    if world is None:
        if isinstance(motion, Skeleton):
            raise InputError("Expected a take's world poses with a skeleton alone, got none")
        world = forward_kinematics(motion)
    quats, positions = world
    keep = pose_sample(quats.shape[0])
    if keep is not None:
        quats, positions = quats[keep], positions[keep]
        ignore = None if ignore is None else ignore[keep]
    body = {arms: body_axes(rig, positions, arms) for arms in (True, False)}
    framing = SegmentFraming(skeleton, rig, quats, positions, ignore, body)
    roles, joints, parents, frames, parent_frames = [], [], [], [], []
    for (side, role), joint in keys.items():
        frames.append(framing.frame_of(side, role, joint))
        parent_role = PARENT_ROLE.get(role)
        parent = rig.joint(side, parent_role) if parent_role else None
        if parent is not None and parent_role is not None:
            parent_frames.append(framing.frame_of(side, parent_role, parent))
        else:
            parent = int(skeleton.parents[joint])
            if parent < 0:
                raise InputError(f"Expected role joint {skeleton.names[joint]!r} to have a parent")
            parent_frames.append(framing.body_frame(role, joint, parent))
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
