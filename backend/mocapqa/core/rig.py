"""Rig roles: which joint is the left upper arm, the right lower leg, and so on.

Names are matched after normalising common rig conventions: CMU/cgspeed and Mixamo
(``LeftArm``, ``mixamorig:LeftForeArm``), Character Creator (``CC_Base_L_Upperarm``), Bandai
(``UpperArm_L``), Unreal (``upperarm_l``) and BVH classics (``RightCollar``, ``RightShoulder``,
``RightElbow``). Helper bones (twist, share, roll, fingers, ``_End`` joints) never take a role,
so the limb chains skip them. Where a rig has both a collar/clavicle and a "shoulder", the
shoulder is the upper arm; otherwise "shoulder" is the clavicle (CMU, Bandai, Mixamo). An
explicit mapping (JSON ``{"joint name": "left_upper_arm", ...}``) overrides the guesses.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal

from mocapqa.core.motion import Skeleton
from mocapqa.errors import InputError

__all__ = [
    "ROLES",
    "SEGMENTS",
    "SIDES",
    "Chain",
    "RigMap",
    "find_roles",
    "limb_chains",
    "role_key",
    "split_side",
]

Side = Literal["left", "right"]
SIDES: tuple[Side, ...] = ("left", "right")
"""The two body sides, in the order roles are listed."""
ROLES = ("clavicle", "upper_arm", "forearm", "hand", "upper_leg", "lower_leg", "foot", "toe")
"""Limb roles, arm then leg, proximal to distal."""
# The limb segments whose twist the twist detector checks (parent role of a chain).
SEGMENTS = ("clavicle", "upper_arm", "forearm", "upper_leg", "lower_leg")

_NAMES: dict[str, str] = {
    "clavicle": "clavicle", "collar": "clavicle", "shoulder": "clavicle",
    "arm": "upper_arm", "upperarm": "upper_arm", "uparm": "upper_arm", "humerus": "upper_arm",
    "forearm": "forearm", "lowerarm": "forearm", "elbow": "forearm", "radius": "forearm",
    "hand": "hand", "wrist": "hand",
    "upleg": "upper_leg", "upperleg": "upper_leg", "thigh": "upper_leg", "hip": "upper_leg",
    "femur": "upper_leg",
    "leg": "lower_leg", "lowerleg": "lower_leg", "calf": "lower_leg", "knee": "lower_leg",
    "shin": "lower_leg", "tibia": "lower_leg",
    "foot": "foot", "ankle": "foot",
    "toe": "toe", "toes": "toe", "toebase": "toe", "ball": "toe", "forefoot": "toe",
}  # fmt: skip
_HELPER = re.compile(r"twist|share|roll|index|thumb|finger|middle|ring|pinky|nub|_end$|end$|dummy")
_PREFIX = re.compile(r"^(.*:)|^(cc_base_|joint_|bip01_|def-|mixamorig)", re.IGNORECASE)


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
    """
    raw = _PREFIX.sub("", name.split(":")[-1])
    raw = _PREFIX.sub("", raw)
    low = raw.lower()
    side: Side | None = None
    rest = low
    patterns: list[tuple[str, int, int]] = [
        (r"^(left|right)[_.\s-]?(.+)$", 1, 2),
        (r"^(l|r)[_.\s-](.+)$", 1, 2),
        (r"^(.+?)[_.\s-](l|r|left|right)$", 2, 1),
        (r"^(.+?)(left|right)$", 2, 1),
    ]
    for pattern, side_group, rest_group in patterns:
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


def role_key(side: Side, role: str) -> str:
    """The key of a role in mappings, e.g. ``"left_upper_arm"``."""
    return f"{side}_{role}"


@dataclass(frozen=True, slots=True)
class Chain:
    """A parent → child → grandchild limb chain checked for twist errors.

    Parameters
    ----------
    side : {"left", "right"}
    segment : str
        Role of the parent joint (one of :data:`SEGMENTS`).
    parent, child : int
        Joint indices; ``child`` is a descendant of ``parent``.
    grandchild : int or None
        The joint (or None, for a hand) whose direction from ``child`` gives the azimuth.
    """

    side: Side
    segment: str
    parent: int
    child: int
    grandchild: int | None


@dataclass(frozen=True, slots=True)
class RigMap:
    """Roles found on a skeleton.

    Parameters
    ----------
    roles : dict
        ``role_key(side, role)`` → joint index.
    unmapped : tuple of str
        Role keys not found.
    """

    roles: dict[str, int]
    unmapped: tuple[str, ...]

    def joint(self, side: Side, role: str) -> int | None:
        """Index of the joint with that role, or None."""
        return self.roles.get(role_key(side, role))


def _is_descendant(skeleton: Skeleton, joint: int, ancestor: int) -> bool:
    p = int(skeleton.parents[joint])
    while p >= 0:
        if p == ancestor:
            return True
        p = int(skeleton.parents[p])
    return False


def find_roles(skeleton: Skeleton, mapping: dict[str, str] | None = None) -> RigMap:
    """Map joints to limb roles.

    Parameters
    ----------
    skeleton : Skeleton
    mapping : dict, optional
        Joint name → role key (``"left_upper_arm"``) overriding the automatic guesses.

    Returns
    -------
    RigMap

    Raises
    ------
    InputError
        If ``mapping`` names a joint or a role that does not exist.
    """
    depths = skeleton.depths
    candidates: dict[str, list[int]] = {}
    has_collar: dict[str, bool] = {"left": False, "right": False}
    parsed: list[tuple[Side | None, str]] = [split_side(n) for n in skeleton.names]
    for side, rest in parsed:
        if side and rest in ("collar", "clavicle"):
            has_collar[side] = True
    for j, (side, rest) in enumerate(parsed):
        if side is None or _HELPER.search(rest) or _HELPER.search(skeleton.names[j].lower()):
            continue
        role = _NAMES.get(rest)
        if role is None:
            continue
        if rest == "shoulder" and has_collar[side]:
            role = "upper_arm"
        candidates.setdefault(role_key(side, role), []).append(j)
    roles = {key: min(js, key=lambda j: depths[j]) for key, js in candidates.items()}
    if mapping:
        valid = {role_key(s, r) for s in SIDES for r in ROLES}
        for joint_name, key in mapping.items():
            if key not in valid:
                raise InputError(f"Expected a role in {sorted(valid)}, got {key!r}")
            try:
                roles[key] = skeleton.index(joint_name)
            except KeyError:
                raise InputError(f"Expected a joint of this skeleton, got {joint_name!r}") from None
    # Keep only roles whose limb order holds (each a descendant of the previous one).
    for side in SIDES:
        for limb in (ROLES[:4], ROLES[4:]):
            previous: int | None = None
            for role in limb:
                key = role_key(side, role)
                if key not in roles:
                    continue
                if previous is not None and not _is_descendant(skeleton, roles[key], previous):
                    del roles[key]
                    continue
                previous = roles[key]
    unmapped = tuple(role_key(s, r) for s in SIDES for r in ROLES if role_key(s, r) not in roles)
    return RigMap(roles=roles, unmapped=unmapped)


def limb_chains(rig: RigMap) -> list[Chain]:
    """The parent → child → grandchild chains that the twist detector checks.

    Clavicle → upper arm → forearm, upper arm → forearm → hand, forearm → hand → (hand axes),
    upper leg → lower leg → foot and lower leg → foot → toe, on both sides, where found.
    """
    triples = (
        ("clavicle", "upper_arm", "forearm"),
        ("upper_arm", "forearm", "hand"),
        ("forearm", "hand", None),
        ("upper_leg", "lower_leg", "foot"),
        ("lower_leg", "foot", "toe"),
    )
    chains: list[Chain] = []
    for side in SIDES:
        for parent_role, child_role, grand_role in triples:
            parent = rig.joint(side, parent_role)
            child = rig.joint(side, child_role)
            if parent is None or child is None:
                continue
            grandchild = rig.joint(side, grand_role) if grand_role else None
            if grand_role is not None and grandchild is None:
                continue
            chains.append(Chain(side, parent_role, parent, child, grandchild))
    return chains
