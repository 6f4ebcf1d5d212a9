"""How each role joint's canonical frame is measured from a take's world poses.

The steps of :func:`mocapqa.limits.canonical.canonical_frames` (its module notes give the
method): the body's left and up axes, each segment's long axis in its joint's frame, its
flexion axis (the weighted circular median of its limb plane's normal) and the frame they make.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Skeleton
from mocapqa.core.rig import RigMap, Side
from mocapqa.errors import InputError
from mocapqa.kinematics.quaternion import conjugate, rotate

__all__ = ["PARENT_ROLE", "SegmentFraming", "body_axes"]

PARENT_ROLE = {
    "upper_arm": "clavicle",
    "forearm": "upper_arm",
    "hand": "forearm",
    "lower_leg": "upper_leg",
    "foot": "lower_leg",
}
"""The role whose anatomical frame each role's rotation is taken relative to (others: the
body)."""

_DISTAL_ROLE = {
    "clavicle": "upper_arm",
    "upper_arm": "forearm",
    "forearm": "hand",
    "upper_leg": "lower_leg",
    "lower_leg": "foot",
    "foot": "toe",
}
_FLEXION_AXIS = np.array([1.0, 0.0, 0.0])
_MIN_BEND_SIN2 = float(np.sin(np.deg2rad(10.0)) ** 2)
_ARM_ROLES = ("clavicle", "upper_arm", "forearm", "hand")


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


def body_axes(rig: RigMap, positions: FloatArray, arms: bool) -> tuple[FloatArray, FloatArray]:
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


@dataclass(frozen=True, slots=True)
class SegmentFraming:
    """The world poses of one take (or of a rig's pooled takes) and its roles, with the long
    axes and frames found so far: the steps of
    :func:`mocapqa.limits.canonical.canonical_frames`.

    ``quats`` ``(F, J, 4)`` and ``positions`` ``(F, J, 3)`` are the sampled world poses,
    ``ignore`` ``(F, J)`` the frames that must not set a flexion axis, ``body`` the body's
    left and up axes ``(F, 3)`` keyed by whether they are the arms'.
    """

    skeleton: Skeleton
    rig: RigMap
    quats: FloatArray
    positions: FloatArray
    ignore: BoolArray | None
    body: dict[bool, tuple[FloatArray, FloatArray]]
    frames: dict[int, FloatArray] = field(default_factory=dict)
    long_axes: dict[int, FloatArray] = field(default_factory=dict)

    def mean_direction(self, joint: int, vectors: FloatArray) -> FloatArray | None:
        """The mean direction of world vectors ``(F, 3)`` seen from the joint's frame; None
        when they are all (nearly) zero, a bone of no length."""
        if np.median(np.linalg.norm(vectors, axis=-1)) < 1e-6:
            return None
        mean = np.mean(_unit(_local(self.quats[:, joint], vectors)), axis=0)
        return _unit(mean) if np.linalg.norm(mean) > 1e-6 else None

    def long_axis(self, side: Side, role: str, joint: int) -> FloatArray:
        """The segment's long axis in the joint's frame, shape (3,).

        Raises
        ------
        InputError
            If the segment has no bone of non-zero length toward the next joint of its limb.
        """
        rig, positions, skeleton = self.rig, self.positions, self.skeleton
        distal = rig.joint(side, _DISTAL_ROLE[role]) if role in _DISTAL_ROLE else None
        if distal is not None:
            axis = self.mean_direction(joint, positions[:, distal] - positions[:, joint])
        elif role == "hand":
            # A hand continues its forearm's bone (from the forearm joint, so that a helper
            # bone of no length between them does not matter), seen from its own frame, on
            # average over the frames: CMU and Bandai hands have no knuckle offsets, and
            # pointing the others at theirs read the Character Creator wrist 10-14 degrees
            # flexed against those rigs. The knuckles only stand in for a hand at its forearm.
            forearm = rig.joint(side, "forearm")
            anchor = int(skeleton.parents[joint]) if forearm is None else forearm
            axis = self.mean_direction(joint, positions[:, joint] - positions[:, anchor])
            if axis is None:
                axis = _end_axis(skeleton, joint)
        else:
            # A foot without a toe points to its End Site, or else continues its parent's bone.
            axis = _end_axis(skeleton, joint)
            if axis is None:
                parent = int(skeleton.parents[joint])
                axis = self.mean_direction(joint, positions[:, joint] - positions[:, parent])
        if axis is None:
            raise InputError(
                f"Expected the {side} {role.replace('_', ' ')} ({skeleton.names[joint]!r}) to "
                f"have a bone of non-zero length toward the next joint of its limb; its long "
                f"axis cannot be found (check the role mapping)"
            )
        return axis

    def world_long(self, side: Side, role: str, joint: int) -> FloatArray:
        """The segment's long axis in the world, per frame, shape (F, 3)."""
        if joint not in self.long_axes:
            self.long_axes[joint] = self.long_axis(side, role, joint)
        axis = np.broadcast_to(self.long_axes[joint], (self.quats.shape[0], 3))
        return rotate(self.quats[:, joint], axis)

    def plane_partner(self, side: Side, role: str) -> tuple[FloatArray, FloatArray]:
        """The world direction ``(F, 3)`` spanning the segment's limb plane with its long
        axis, and the world direction ``(F, 3)`` its flexion axis is signed toward."""
        left_w, up_w = self.body[role in _ARM_ROLES]
        if role == "clavicle":
            return up_w, np.cross(left_w, up_w)
        other = _DISTAL_ROLE[role] if role in ("upper_arm", "upper_leg") else PARENT_ROLE[role]
        joint = self.rig.joint(side, other)
        return (self.world_long(side, other, joint) if joint is not None else left_w), left_w

    def frame_of(self, side: Side, role: str, joint: int) -> FloatArray:
        """``C_j`` of a role joint, a unit quaternion (scalar-last), shape (4,).

        Raises
        ------
        InputError
            If the segment runs along the body's left-right axis.
        """
        if joint in self.frames:
            return self.frames[joint]
        quats, ignore = self.quats, self.ignore
        along = self.world_long(side, role, joint)
        partner, sign_w = self.plane_partner(side, role)
        forearm = self.rig.joint(side, "forearm") if role == "hand" else None
        skip = None if ignore is None else ignore[:, joint]
        if ignore is not None and skip is not None and forearm is not None:
            skip = skip | ignore[:, forearm]
        kept = slice(None) if skip is None or skip.all() else ~skip
        sign_ref = np.mean(_local(quats[kept, joint], sign_w[kept]), axis=0)
        if forearm is not None:
            # The wrist hardly bends, so its bend plane is a weak, rig-dependent signal: the
            # hand takes the forearm's flexion axis, as seen from its own frame.
            forearm_x = rotate(self.frame_of(side, "forearm", forearm), _FLEXION_AXIS)
            normals = _local(quats[:, joint], rotate(quats[:, forearm], forearm_x[None]))
        else:
            normals = _local(quats[:, joint], np.cross(along, partner))
        long_axis = self.long_axes[joint]
        flexion, bend = _median_direction(normals, long_axis, sign_ref, skip)
        if bend < _MIN_BEND_SIN2 or _parallel(flexion, long_axis):
            flexion = sign_ref
        if _parallel(flexion, long_axis):
            # A segment along the body's left-right axis on average (a mapping that names an
            # arm joint for a leg role): no flexion axis can be found for it.
            raise InputError(
                f"Expected the {side} {role.replace('_', ' ')} "
                f"({self.skeleton.names[joint]!r}) to run across the body's left-right axis, "
                "got a segment along it; its flexion axis cannot be found (check the role "
                "mapping)"
            )
        self.frames[joint] = _frame_quat(flexion, long_axis)
        return self.frames[joint]

    def body_frame(self, role: str, joint: int, parent: int) -> FloatArray:
        """The body frame in the skeleton parent's frame, the parent frame of a role with no
        parent role (a clavicle, an upper leg), shape (4,).

        Raises
        ------
        InputError
            If the body's left-right and up axes run along each other.
        """
        left_w, up_w = self.body[role in _ARM_ROLES]
        left_l = np.mean(_local(self.quats[:, parent], left_w), axis=0)
        up_l = np.mean(_local(self.quats[:, parent], up_w), axis=0)
        if _parallel(left_l, up_l):
            # Hips or shoulders stacked along the up axis (a mapping that names an arm
            # joint for a leg role): no body frame.
            raise InputError(
                "Expected the body's left-right axis (hips, shoulders) across its up axis "
                f"(hips to shoulders), got the two along each other, framing "
                f"{self.skeleton.names[joint]!r} (check the role mapping)"
            )
        # Legs hang: their body frame's long axis points down, so standing is near identity.
        return _frame_quat(left_l, up_l if role in _ARM_ROLES else -up_l)
