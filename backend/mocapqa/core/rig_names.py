"""Joint-name conventions of the rigs people have: sides, prefixes, limb tokens, helper bones.

A joint name is split into a side and a *token* (``"mixamorig2:LeftForeArm"`` → left,
``forearm``; ``"Bip01 L UpperArm"`` → left, ``upperarm``; ``"upperarm01.L"`` → left,
``upperarm``). Each token names the limb *levels* it may stand for; a few are ambiguous across
conventions and are resolved by the skeleton's structure in :func:`mocapqa.core.rig.find_roles`:

* ``shoulder`` is the clavicle in CMU, HumanIK/Maya, Mixamo, Perception Neuron, Rokoko and
  Bandai (``LeftShoulder → LeftArm``), but the upper arm in Xsens MVN and Biovision-style BVH
  (``LeftCollar → LeftShoulder → LeftElbow``) and SMPL (``left_collar → left_shoulder``);
* ``leg`` is the shin in HumanIK/CMU (``LeftUpLeg → LeftLeg``) but the thigh where a lower-leg
  joint follows it (``LeftLeg → LeftLowerLeg``);
* ``foot`` is the foot, except under an ``ankle`` (SMPL's ``left_ankle → left_foot``), where it
  is the toe.

Names are matched case-insensitively, after removing namespace (``anything:``) and rig prefixes
(``CC_Base_``, ``Bip01``/``Bip001``, ``mixamorig``/``mixamorigN``, ``Character1_``, ``DEF-``,
VRM's ``J_Bip_``).
Trailing digits are dropped (MakeHuman's ``upperarm01``/``upperarm02``, Biped's ``Toe0``).
"""

from __future__ import annotations

import functools
import re
from typing import Literal

__all__ = ["ARM_TOKENS", "LEG_TOKENS", "Side", "is_helper", "split_side", "token_of"]

Side = Literal["left", "right"]
"""A body side."""

ARM_TOKENS: dict[str, tuple[int, ...]] = {
    "clavicle": (0,), "collar": (0,),
    "shoulder": (0, 1),
    "arm": (1,), "upperarm": (1,), "uparm": (1,), "humerus": (1,),
    "forearm": (2,), "lowerarm": (2,), "lowarm": (2,), "loarm": (2,), "elbow": (2,),
    "radius": (2,),
    "hand": (3,), "wrist": (3,),
}  # fmt: skip
"""Arm token → possible levels (0 clavicle, 1 upper arm, 2 forearm, 3 hand)."""

LEG_TOKENS: dict[str, tuple[int, ...]] = {
    "upleg": (0,), "upperleg": (0,), "thigh": (0,), "hip": (0,), "femur": (0,),
    "leg": (0, 1),
    "lowerleg": (1,), "lowleg": (1,), "loleg": (1,), "calf": (1,), "knee": (1,), "shin": (1,),
    "tibia": (1,),
    "ankle": (2,),
    "foot": (2, 3),
    "toe": (3,), "toes": (3,), "toebase": (3,), "ball": (3,), "forefoot": (3,),
}  # fmt: skip
"""Leg token → possible levels (0 upper leg, 1 lower leg, 2 foot, 3 toe)."""

_HELPER = re.compile(
    r"twist|share|roll|index|thumb|finger|middle|ring|pinky|nub|_end$|end$|dummy|tip$|helper"
)
_PREFIX = re.compile(
    r"^(cc_base_|joint_|bip0*1[ _]|def-|mixamorig\d*[:_]?|character\d*_|j_bip_)", re.IGNORECASE
)
_SIDE_PATTERNS: tuple[tuple[str, int, int], ...] = (
    (r"^(left|right)[_.\s-]?(.+)$", 1, 2),
    (r"^(l|r)[_.\s-](.+)$", 1, 2),
    (r"^(.+?)[_.\s-](l|r|left|right)$", 2, 1),
    (r"^(.+?)(left|right)$", 2, 1),
)


def _strip(name: str) -> str:
    raw = name.split(":")[-1]
    for _ in range(2):
        raw = _PREFIX.sub("", raw)
    return raw


def split_side(name: str) -> tuple[Side | None, str]:
    """Split a joint name into its side and the normalised rest.

    Examples
    --------
    >>> split_side("mixamorig:LeftForeArm")
    ('left', 'forearm')
    >>> split_side("UpperArm_L")
    ('left', 'upperarm')
    >>> split_side("CC_Base_R_Calf")
    ('right', 'calf')
    >>> split_side("Bip01 L UpperArm")
    ('left', 'upperarm')
    """
    return _split_side(name)


@functools.lru_cache(maxsize=4096)
def _split_side(name: str) -> tuple[Side | None, str]:
    raw = _strip(name)
    low = raw.lower()
    side: Side | None = None
    rest = low
    for pattern, side_group, rest_group in _SIDE_PATTERNS:
        match = re.match(pattern, low)
        if match:
            side = "left" if match.group(side_group).startswith("l") else "right"
            rest = match.group(rest_group)
            break
    else:
        # CMU style "LHipJoint", "RThumb": one capital L/R before another capital.
        match = re.match(r"^([LR])([A-Z].*)$", raw)
        if match:
            side = "left" if match.group(1) == "L" else "right"
            rest = match.group(2).lower()
    return side, re.sub(r"[_.\s-]", "", rest)


def is_helper(name: str) -> bool:
    """Whether a joint is a helper bone that never takes a role.

    Twist, roll and share bones, fingers, ``_End``/``Nub``/``Tip`` joints, and MakeHuman's
    ``__`` bones (``__UpArm_L``) are helpers.
    """
    return _is_helper(name)


@functools.lru_cache(maxsize=4096)
def _is_helper(name: str) -> bool:
    if _strip(name).startswith("__"):
        return True
    _, rest = split_side(name)
    return bool(_HELPER.search(rest) or _HELPER.search(name.lower()))


def token_of(rest: str) -> str:
    """The limb token of a normalised name, without trailing digits (``upperarm01``: upperarm)."""
    return rest.rstrip("0123456789")
