"""Rig roles: which joint is the left upper arm, the right lower leg, and so on.

Roles are found from joint names *and* the skeleton's structure. The names of
:mod:`mocapqa.core.rig_names` give each joint a side and a limb token (CMU/cgspeed, HumanIK/Maya,
Mixamo with any ``mixamorigN:`` prefix, Perception Neuron, Rokoko, Xsens MVN, 3ds Max Biped,
MakeHuman classic and default, Biovision, Unity/Unreal humanoid, SMPL, Character Creator,
Bandai). Tokens that mean different joints in different conventions (``shoulder``, ``leg``,
``foot``) are then resolved along each limb chain: the named joints of one side's arm (or leg)
are ordered from the body outwards, and the levels (clavicle, upper arm, forearm, hand) are
assigned so that they increase along the chain, fill as many roles as possible without holes,
prefer unambiguous names, and keep consecutive roles close in the tree. So ``LeftShoulder`` is
the clavicle above ``LeftArm`` (CMU) and the upper arm below ``LeftCollar`` and above
``LeftElbow`` (Xsens). Helper bones (twist, share, roll, fingers, ``_End``, MakeHuman's ``__``
bones) never take a role.

An explicit mapping overrides the guesses, role key → joint name
(``{"left_upper_arm": "LeftShoulder", ...}``); the older orientation, joint name → role key, is
accepted too (see :func:`normalise_mapping`).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

from mocapqa.core.motion import Skeleton
from mocapqa.core.rig_names import ARM_TOKENS, LEG_TOKENS, is_helper, split_side, token_of
from mocapqa.errors import InputError

__all__ = [
    "ROLES",
    "ROLE_KEYS",
    "SEGMENTS",
    "SIDES",
    "Chain",
    "RigMap",
    "find_roles",
    "limb_chains",
    "mapped_roles",
    "normalise_mapping",
    "require_mapped",
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
_LIMBS: tuple[tuple[tuple[str, ...], dict[str, tuple[int, ...]]], ...] = (
    (ROLES[:4], ARM_TOKENS),
    (ROLES[4:], LEG_TOKENS),
)


def role_key(side: Side, role: str) -> str:
    """The key of a role in mappings, e.g. ``"left_upper_arm"``."""
    return f"{side}_{role}"


ROLE_KEYS: tuple[str, ...] = tuple(role_key(s, r) for s in SIDES for r in ROLES)
"""Every role key, left side first, in :data:`ROLES` order."""


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


Score = tuple[int, int, int, int]
"""(roles filled, −holes between them, unambiguous names, −tree distance between roles)."""


@functools.lru_cache(maxsize=256)
def _assign(
    levels: tuple[tuple[int, ...], ...], depths: tuple[int, ...]
) -> tuple[Score, tuple[int, ...]]:
    """Best strictly increasing level per chain entry (−1: no role), by :data:`Score`.

    A small dynamic programme over (entry, last level used, last entry given a level); chains
    hold a handful of named joints, and the same chain shapes recur, hence the cache.
    """
    memo: dict[tuple[int, int, int], tuple[Score, tuple[int, ...]]] = {}

    def best(i: int, last: int, prev: int) -> tuple[Score, tuple[int, ...]]:
        key = (i, last, prev)
        if key in memo:
            return memo[key]
        if i == len(levels):
            return (0, 0, 0, 0), ()
        score, rest = best(i + 1, last, prev)
        choice: tuple[Score, tuple[int, ...]] = (score, (-1, *rest))
        for level in levels[i]:
            if level <= last:
                continue
            sub, tail = best(i + 1, level, i)
            holes = level - last - 1 if last >= 0 else 0
            span = depths[i] - depths[prev] if prev >= 0 else 0
            total: Score = (
                sub[0] + 1,
                sub[1] - holes,
                sub[2] + (1 if len(levels[i]) == 1 else 0),
                sub[3] - span,
            )
            if total > choice[0]:
                choice = (total, (level, *tail))
        memo[key] = choice
        return choice

    return best(0, -1, -1)


def _limb_roles(
    skeleton: Skeleton, candidates: list[tuple[int, str]], tokens: dict[str, tuple[int, ...]]
) -> dict[int, int]:
    """Level → joint for one side's limb, from its named joints ``(joint, token)``."""
    depths = skeleton.depths
    best_score: Score | None = None
    best_roles: dict[int, int] = {}
    joints = [j for j, _ in candidates]
    # Only the outermost named joints end a chain worth scoring: a chain ending higher up is
    # a part of one of theirs.
    ends = [e for e in joints if not any(_is_descendant(skeleton, j, e) for j in joints)]
    for end in ends:
        chain = sorted(
            ((j, t) for j, t in candidates if j == end or _is_descendant(skeleton, end, j)),
            key=lambda item: int(depths[item[0]]),
        )
        # Consecutive joints with one token (upperarm01, upperarm02) are one segment: the first.
        merged: list[tuple[int, str]] = []
        for joint, token in chain:
            if not merged or merged[-1][1] != token:
                merged.append((joint, token))
        score, levels = _assign(
            tuple(tokens[t] for _, t in merged), tuple(int(depths[j]) for j, _ in merged)
        )
        if best_score is None or score > best_score:
            best_score = score
            best_roles = {lv: merged[k][0] for k, lv in enumerate(levels) if lv >= 0}
    return best_roles


def normalise_mapping(mapping: Mapping[str, str]) -> dict[str, str]:
    """A mapping as role key → joint name.

    Parameters
    ----------
    mapping : mapping of str to str
        Either role key → joint name (``{"left_upper_arm": "LeftShoulder"}``) or, as older
        mapping files have it, joint name → role key (``{"LeftShoulder": "left_upper_arm"}``).

    Raises
    ------
    InputError
        If neither all keys nor all values are role keys, a value is not a string, or one
        joint is named for two roles.
    """
    if not all(isinstance(k, str) and isinstance(v, str) for k, v in mapping.items()):
        raise InputError("Expected a mapping of role keys to joint names (strings)")
    valid = set(ROLE_KEYS)
    if all(k in valid for k in mapping):
        roles_of: dict[str, str] = {}
        for key, joint in mapping.items():
            if joint in roles_of:
                raise InputError(
                    f"Expected one role per joint, got {joint!r} for {roles_of[joint]} and {key}"
                )
            roles_of[joint] = key
        return dict(mapping)
    if all(v in valid for v in mapping.values()):
        inverted: dict[str, str] = {}
        for joint, key in mapping.items():
            if key in inverted:
                raise InputError(f"Expected one joint per role, got two for {key!r}")
            inverted[key] = joint
        return inverted
    key, joint = next(
        ((k, v) for k, v in mapping.items() if k not in valid and v not in valid),
        next((k, v) for k, v in mapping.items() if k not in valid),
    )
    raise InputError(
        f"Expected a role in {sorted(valid)} as every key (or every value), got {key!r}: {joint!r}"
    )


def find_roles(skeleton: Skeleton, mapping: Mapping[str, str] | None = None) -> RigMap:
    """Map joints to limb roles.

    Parameters
    ----------
    skeleton : Skeleton
    mapping : mapping, optional
        Role key → joint name (or joint name → role key, see :func:`normalise_mapping`)
        overriding the automatic guesses.

    Returns
    -------
    RigMap

    Raises
    ------
    InputError
        If ``mapping`` names a joint or a role that does not exist.
    """
    parsed = [split_side(n) for n in skeleton.names]
    roles: dict[str, int] = {}
    for side in SIDES:
        for limb_roles, tokens in _LIMBS:
            candidates = [
                (j, token_of(rest))
                for j, (s, rest) in enumerate(parsed)
                if s == side and token_of(rest) in tokens and not is_helper(skeleton.names[j])
            ]
            for level, joint in _limb_roles(skeleton, candidates, tokens).items():
                roles[role_key(side, limb_roles[level])] = joint
    mapped: set[str] = set()
    if mapping:
        for key, joint_name in normalise_mapping(mapping).items():
            try:
                joint = skeleton.index(joint_name)
            except KeyError:
                raise InputError(
                    f"Expected the mapping's joint for {key} to be a joint of this skeleton, "
                    f"got {joint_name!r}"
                ) from None
            # A joint the mapping gives a role loses any role found for it by name.
            for other in [k for k, j in roles.items() if j == joint and k != key]:
                del roles[other]
            roles[key] = joint
            mapped.add(key)
    # Keep only roles whose limb order holds (each a descendant of the previous one). A role
    # found by name that breaks it is dropped; one the mapping gave is an error, not dropped
    # silently: the mapping says something about the rig that cannot be.
    for side in SIDES:
        for limb_roles, _ in _LIMBS:
            previous: str | None = None
            for role in limb_roles:
                key = role_key(side, role)
                if key not in roles:
                    continue
                if previous is not None and not _is_descendant(
                    skeleton, roles[key], roles[previous]
                ):
                    if key in mapped:
                        raise InputError(
                            f"Expected the mapping's joint for {key} "
                            f"({skeleton.names[roles[key]]!r}) below the {previous} "
                            f"({skeleton.names[roles[previous]]!r}) in the hierarchy, got a "
                            f"joint that is not its descendant"
                            + ("" if previous in mapped else f" (map {previous} too)")
                        )
                    del roles[key]
                    continue
                previous = key
    unmapped = tuple(key for key in ROLE_KEYS if key not in roles)
    return RigMap(roles=roles, unmapped=unmapped)


def mapped_roles(skeleton: Skeleton, mapping: Mapping[str, str] | None) -> RigMap:
    """:func:`find_roles` with ``mapping`` where the skeleton has every joint it names, else
    without it: a folder of several rigs is mapped with one rig's mapping, which applies to
    that rig's takes only."""
    if mapping and all(name in skeleton.names for name in normalise_mapping(mapping).values()):
        return find_roles(skeleton, mapping)
    return find_roles(skeleton)


def require_mapped(mapping: Mapping[str, str] | None, skeletons: Sequence[Skeleton]) -> None:
    """Refuse a mapping that :func:`mapped_roles` would apply to none of ``skeletons`` (a
    mapping of another rig, a misspelt joint).

    Raises
    ------
    InputError
        Naming the joints no skeleton has all of.
    """
    if not mapping:
        return
    names = set(normalise_mapping(mapping).values())
    if not any(names <= set(s.names) for s in skeletons):
        raise InputError(
            f"Expected a take with every joint the mapping names ({', '.join(sorted(names))}), "
            "got none"
        )


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
