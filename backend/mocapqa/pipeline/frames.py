"""Point positions for the 3D view.

The 3D view draws joints and End Sites as points joined to their parents. Positions are
``(F, P, 3)`` in file units, with the P points in skeleton order followed by the End Sites.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Motion
from mocapqa.kinematics.forward import end_site_positions, forward_kinematics

__all__ = ["MOVING_SHARE", "motion_points", "motion_pose", "rigid_bones"]

MOVING_SHARE = 0.01
"""A joint whose translation from its parent moves by more than this share of the median
bone length over a take is not joined to its parent by a bone (:func:`rigid_bones`)."""


def motion_points(motion: Motion) -> tuple[list[str], list[int], FloatArray]:
    """Names, parents and world positions of the joints and End Sites of a motion.

    Returns
    -------
    names : list of str
        Joint names, then ``"<parent> end"`` per End Site.
    parents : list of int
        Parent point index per point (-1 for roots).
    positions : ndarray, shape (F, P, 3)
        World positions, file units.
    """
    names, parents, positions, _ = motion_pose(motion)
    return names, parents, positions


def motion_pose(motion: Motion) -> tuple[list[str], list[int], FloatArray, FloatArray]:
    """:func:`motion_points` plus the world rotation of every point.

    The 3D view draws each bone in its parent joint's frame, so a roll about the bone shows.

    Returns
    -------
    names, parents, positions
        As :func:`motion_points`.
    rotations : ndarray, shape (F, P, 4)
        World unit quaternions, scalar-last ``(x, y, z, w)``; an End Site carries its parent's.
    """
    world_quats, world_positions = forward_kinematics(motion)
    ends = end_site_positions(motion, world_quats, world_positions)
    skeleton = motion.skeleton
    names = list(skeleton.names) + [f"{skeleton.names[e.parent]} end" for e in skeleton.end_sites]
    site_parents = [int(e.parent) for e in skeleton.end_sites]
    parents = [int(p) for p in skeleton.parents] + site_parents
    positions = np.concatenate([world_positions, ends], axis=1)
    rotations = np.concatenate([world_quats, world_quats[:, site_parents]], axis=1)
    return names, parents, positions, rotations


def rigid_bones(motion: Motion) -> list[list[int]]:
    """The ``[parent, point]`` pairs the 3D view draws as bones, in :func:`motion_points`'
    point order: every joint and End Site joined to its parent, except a joint whose
    translation from its parent moves during the take (by more than :data:`MOVING_SHARE` of
    the median OFFSET length).

    Such a joint carries the take's travel, as Bandai's ``Hips`` under a ``joint_Root`` that
    stays at the origin: a "bone" to it would stretch across the room.
    """
    skeleton = motion.skeleton
    local = motion.local_translations()
    moved = np.linalg.norm(local - local[:1], axis=2).max(axis=0) if motion.n_frames else None
    lengths = np.linalg.norm(skeleton.offsets, axis=1)
    scale = float(np.median(lengths[lengths > 0])) if (lengths > 0).any() else 1.0
    bones = [
        [int(parent), joint]
        for joint, parent in enumerate(skeleton.parents)
        if parent >= 0 and (moved is None or moved[joint] <= MOVING_SHARE * scale)
    ]
    first_site = skeleton.n_joints
    bones += [[int(e.parent), first_site + k] for k, e in enumerate(skeleton.end_sites)]
    return bones
