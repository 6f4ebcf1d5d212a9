"""Analytic two-bone IK on a leg: move the ankle to a target, keep the knee's plane and the
foot's world orientation, change only the leg's joint rotations.

Conventions
-----------
* Quaternions are scalar-last ``(x, y, z, w)`` (:mod:`mocapqa.kinematics.quaternion`), world
  rotations and positions come from :func:`mocapqa.kinematics.forward.forward_kinematics`;
  ``world_rot[j] = world_rot[parent] ⊗ local[j]``.
* The leg is three joints of the rig: the hip (``upper_leg`` role), the knee (``lower_leg``)
  and the ankle (``foot``). Joints between them (twist or roll bones) keep their local
  rotations, so the solver needs no direct parent–child links.
* The solve: with the thigh ``l1 = |K − H|`` and the shank ``l2 = |A − K|`` of the frame, the
  new knee lies in the plane through the hip, the target and the raw knee (the pole is the raw
  knee's offset from the hip → target line), at the one place that gives both lengths. The hip
  turns by the shortest arc taking the raw knee there, the knee by the shortest arc taking the
  turned shank onto the target. The ankle's local rotation is then set so that its world
  rotation (the foot's orientation) is the raw one.
* A target farther from the hip than ``l1 + l2`` (or nearer than ``|l1 − l2|``) is out of reach:
  the ankle goes as far as the leg allows along the hip → target line, and the frame is
  reported clamped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Skeleton
from mocapqa.errors import InputError
from mocapqa.kinematics.quaternion import conjugate, multiply, normalize, rotate

__all__ = ["Leg", "leg_subtree", "shortest_arc", "solve_leg"]

_REACH_MARGIN = 1e-9
"""Relative margin kept inside the reachable range, so the knee angle's cosine stays in [−1, 1]."""
_DEGENERATE_POLE = 1e-6
"""A pole shorter than this (thigh lengths) has no direction: the leg is straight toward the
target in that frame, and the mean pole direction of the other frames is used."""


@dataclass(frozen=True, slots=True)
class Leg:
    """The three joints of one leg.

    Parameters
    ----------
    hip, knee, ankle : int
        Joint indices (``upper_leg``, ``lower_leg`` and ``foot`` roles); ``knee`` descends from
        ``hip`` and ``ankle`` from ``knee``.
    """

    hip: int
    knee: int
    ankle: int


def leg_subtree(skeleton: Skeleton, hip: int) -> BoolArray:
    """Which joints descend from ``hip`` (the hip included): the joints a leg IK can move.

    Returns
    -------
    ndarray of bool, shape (J,)
    """
    inside = np.zeros(skeleton.n_joints, dtype=bool)
    inside[hip] = True
    for joint in range(hip + 1, skeleton.n_joints):  # parents precede their children
        parent = int(skeleton.parents[joint])
        inside[joint] = parent >= 0 and bool(inside[parent])
    return inside


def _check_leg(skeleton: Skeleton, leg: Leg) -> None:
    """Raise InputError unless ankle descends from knee and knee from hip."""

    def descends(joint: int, ancestor: int) -> bool:
        parent = int(skeleton.parents[joint])
        while parent >= 0:
            if parent == ancestor:
                return True
            parent = int(skeleton.parents[parent])
        return False

    if not (descends(leg.knee, leg.hip) and descends(leg.ankle, leg.knee)):
        names = skeleton.names
        raise InputError(
            f"Expected a leg chain hip → knee → ankle, got {names[leg.hip]!r}, "
            f"{names[leg.knee]!r}, {names[leg.ankle]!r} not descending from one another"
        )


def shortest_arc(a: FloatArray, b: FloatArray) -> FloatArray:
    """Unit quaternions ``(N, 4)`` of the shortest rotation taking directions ``a`` onto ``b``.

    Parameters
    ----------
    a, b : ndarray, shape (N, 3)
        Non-zero vectors (lengths ignored), not opposite.

    Returns
    -------
    ndarray, shape (N, 4)
        Scalar-last.
    """
    ua = a / np.linalg.norm(a, axis=-1, keepdims=True)
    ub = b / np.linalg.norm(b, axis=-1, keepdims=True)
    q = np.concatenate((np.cross(ua, ub), 1.0 + np.sum(ua * ub, axis=-1, keepdims=True)), axis=-1)
    return normalize(q)


def _knee_positions(
    hip: FloatArray, knee: FloatArray, ankle: FloatArray, target: FloatArray
) -> tuple[FloatArray, FloatArray, BoolArray]:
    """New knee and ankle positions ``(N, 3)`` and the clamped frames ``(N,)``."""
    thigh = knee - hip
    l1 = np.linalg.norm(thigh, axis=-1)
    l2 = np.linalg.norm(ankle - knee, axis=-1)
    reach = target - hip
    distance = np.linalg.norm(reach, axis=-1)
    longest = (l1 + l2) * (1.0 - _REACH_MARGIN)
    shortest = np.abs(l1 - l2) * (1.0 + _REACH_MARGIN) + _REACH_MARGIN * l1
    clamped = (distance > longest) | (distance < shortest)
    d = np.clip(distance, shortest, longest)
    u = reach / np.maximum(distance, np.finfo(np.float64).tiny)[:, None]
    pole = thigh - np.sum(thigh * u, axis=-1, keepdims=True) * u
    pole_length = np.linalg.norm(pole, axis=-1)
    good = pole_length > _DEGENERATE_POLE * l1
    pole_dir = pole / np.where(good, pole_length, 1.0)[:, None]
    if not good.all():
        mean = pole_dir[good].mean(axis=0) if good.any() else np.array([1.0, 0.0, 0.0])
        fallback = mean - np.sum(mean * u, axis=-1, keepdims=True) * u
        fallback /= np.maximum(np.linalg.norm(fallback, axis=-1, keepdims=True), 1e-300)
        pole_dir = np.where(good[:, None], pole_dir, fallback)
    cos_a = np.clip((l1**2 + d**2 - l2**2) / (2.0 * l1 * d), -1.0, 1.0)
    sin_a = np.sqrt(1.0 - cos_a**2)
    new_knee = hip + l1[:, None] * (cos_a[:, None] * u + sin_a[:, None] * pole_dir)
    new_ankle = hip + d[:, None] * u
    return new_knee, new_ankle, clamped


def solve_leg(
    skeleton: Skeleton,
    leg: Leg,
    local_quats: FloatArray,
    world_quats: FloatArray,
    world_positions: FloatArray,
    targets: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Local rotations that put the ankle on the targets, for the frames given.

    Parameters
    ----------
    skeleton : Skeleton
    leg : Leg
    local_quats : ndarray, shape (N, J, 4)
        The frames' local rotations.
    world_quats : ndarray, shape (N, J, 4)
        Their world rotations (forward kinematics of ``local_quats``).
    world_positions : ndarray, shape (N, J, 3)
        Their world positions, take units.
    targets : ndarray, shape (N, 3)
        Where the ankle should be, take units.

    Returns
    -------
    local_quats : ndarray, shape (N, J, 4)
        A copy with the hip's, the knee's and the ankle's local rotations changed; every other
        joint's rotation is the input's, so joints outside the hip's subtree keep their world
        positions and rotations exactly.
    miss : ndarray, shape (N,)
        Distance from the target to where the ankle went: 0 where the target was within
        reach, take units.

    Raises
    ------
    InputError
        If the joints are not a hip → knee → ankle chain.
    """
    _check_leg(skeleton, leg)
    hip = world_positions[:, leg.hip]
    knee = world_positions[:, leg.knee]
    ankle = world_positions[:, leg.ankle]
    new_knee, new_ankle, clamped = _knee_positions(hip, knee, ankle, targets)
    miss = np.where(clamped, np.linalg.norm(targets - new_ankle, axis=-1), 0.0)
    turn_hip = shortest_arc(knee - hip, new_knee - hip)
    shank = rotate(turn_hip, ankle - knee)
    turn_knee = shortest_arc(shank, new_ankle - new_knee)
    turn_leg = multiply(turn_knee, turn_hip)
    parents = skeleton.parents
    hip_parent, knee_parent, ankle_parent = (
        int(parents[j]) for j in (leg.hip, leg.knee, leg.ankle)
    )

    def parent_world(joint: int) -> FloatArray:
        if joint < 0:
            return np.broadcast_to(np.array([0.0, 0.0, 0.0, 1.0]), turn_hip.shape)
        quats: FloatArray = world_quats[:, joint]
        return quats

    out = local_quats.copy()
    # world'[hip] = turn_hip ⊗ world[hip]; its parent is not moved.
    out[:, leg.hip] = normalize(
        multiply(conjugate(parent_world(hip_parent)), multiply(turn_hip, world_quats[:, leg.hip]))
    )
    # The knee's parent is in the hip's subtree: turned by turn_hip.
    new_knee_parent = multiply(turn_hip, parent_world(knee_parent))
    out[:, leg.knee] = normalize(
        multiply(conjugate(new_knee_parent), multiply(turn_leg, world_quats[:, leg.knee]))
    )
    # The ankle's parent is in the knee's subtree: turned by turn_knee ⊗ turn_hip; the
    # ankle keeps its raw world rotation.
    new_ankle_parent = multiply(turn_leg, parent_world(ankle_parent))
    out[:, leg.ankle] = normalize(multiply(conjugate(new_ankle_parent), world_quats[:, leg.ankle]))
    return out, miss
