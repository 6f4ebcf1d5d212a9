"""Which joints a limits model covers, their bone axes, and the rig fingerprint.

A limits model is only meaningful on the rig family it was built from: joint frames, rest
poses and bone-axis conventions differ between rigs (CMU-style T-pose offsets along ±X/−Y,
Character Creator bones along +Y, Bandai bones along +X on the left and −X on the right). The
fingerprint of a skeleton is, for each modelled role, the joint's name and the sign and axis of
its bone direction (``"+x"``, ``"-y"``, ...). A model applies to a skeleton only when every
role the model holds is on the skeleton with the same name and the same axis label.

Bone axis of a joint: the direction of its longest child OFFSET (child joints and End Sites);
when every child offset is (near) zero, the direction of the joint's own OFFSET from its
parent; ``+y`` as a last resort.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Skeleton
from mocapqa.core.rig import SIDES, mapped_roles, role_key

__all__ = [
    "MODELLED_ROLES",
    "RIG_FAMILIES",
    "axis_label",
    "bone_axis",
    "fingerprint_mismatches",
    "rig_family",
    "rig_fingerprint",
]

# The limb roles a limits model holds (toes are left out: most rigs end them in zero offsets).
MODELLED_ROLES = ("clavicle", "upper_arm", "forearm", "hand", "upper_leg", "lower_leg", "foot")

# The labels of :func:`rig_family` a per-rig model can be built for (all but "other").
RIG_FAMILIES = ("bandai", "character_creator", "cmu")

_ZERO_LENGTH = 1e-4


def bone_axis(skeleton: Skeleton, joint: int) -> FloatArray:
    """Unit bone (twist) axis of ``joint`` in its own frame, shape (3,).

    Parameters
    ----------
    skeleton : Skeleton
    joint : int
        Joint index.
    """
    offsets = [skeleton.offsets[c] for c in skeleton.children(joint)]
    offsets += [np.asarray(o, dtype=np.float64) for o in skeleton.end_site_offsets(joint)]
    for candidates in (offsets, [skeleton.offsets[joint]]):
        if candidates:
            longest = max(candidates, key=lambda o: float(np.linalg.norm(o)))
            norm = float(np.linalg.norm(longest))
            if norm > _ZERO_LENGTH:
                return np.asarray(longest / norm, dtype=np.float64)
    return np.array([0.0, 1.0, 0.0])


def axis_label(axis: FloatArray) -> str:
    """Sign and name of the dominant component of ``axis``, e.g. ``"-x"``."""
    i = int(np.argmax(np.abs(axis)))
    return ("+" if axis[i] >= 0 else "-") + "xyz"[i]


def rig_fingerprint(
    skeleton: Skeleton, mapping: Mapping[str, str] | None = None
) -> dict[str, tuple[str, str]]:
    """Role key → (joint name, axis label) for the modelled roles found on ``skeleton``.

    Parameters
    ----------
    skeleton : Skeleton
    mapping : mapping, optional
        Role key → joint name, applied where the skeleton has its joints
        (:func:`mocapqa.core.rig.mapped_roles`).

    Returns
    -------
    dict
        For example ``{"left_upper_arm": ("LeftArm", "+x"), ...}``.
    """
    rig = mapped_roles(skeleton, mapping)
    out: dict[str, tuple[str, str]] = {}
    for side in SIDES:
        for role in MODELLED_ROLES:
            joint = rig.joint(side, role)
            if joint is not None:
                label = axis_label(bone_axis(skeleton, joint))
                out[role_key(side, role)] = (skeleton.names[joint], label)
    return out


def fingerprint_mismatches(expected: dict[str, tuple[str, str]], skeleton: Skeleton) -> list[str]:
    """Human-readable differences between a model's fingerprint and a skeleton's.

    Returns
    -------
    list of str
        Empty when ``skeleton`` has every expected role with the same name and axis.
    """
    found = rig_fingerprint(skeleton)
    problems: list[str] = []
    for key, (name, label) in expected.items():
        if key not in found:
            problems.append(f"role {key}: expected joint {name!r}, got none")
        elif found[key] != (name, label):
            got_name, got_label = found[key]
            problems.append(
                f"role {key}: expected {name!r} with bone axis {label}, "
                f"got {got_name!r} with bone axis {got_label}"
            )
    return problems


def rig_family(skeleton: Skeleton) -> str:
    """A readable family label: ``"character_creator"``, ``"bandai"``, ``"cmu"`` or ``"other"``.

    The label is for people; whether a model applies is decided by the fingerprint.
    """
    names = set(skeleton.names)
    if any(n.startswith("CC_Base_") for n in names):
        return "character_creator"
    if {"UpperArm_L", "LowerArm_L", "UpperLeg_L"} <= names:
        return "bandai"
    if {"LeftArm", "LeftForeArm", "LeftUpLeg", "LeftLeg"} <= names:
        return "cmu"
    return "other"
