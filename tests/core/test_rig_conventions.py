"""Roles on the rigs people have, built by renaming the joints of real corpus takes.

Each convention's names were checked against real public files (see ``tests/data/README.md``,
section "Rig naming conventions"). A test skeleton is a real take's skeleton (the CMU walk or a
seeded choice of Bandai take) with its limb joints renamed to the convention, its hip-side and
finger joints dropped or renamed, the convention's extra joints inserted (MakeHuman's
``shoulder01``/``upperarm02``, twist bones, ``__`` helpers, SMPL's ``left_hand`` under the wrist),
the children of every joint in a seeded random order, and Z-up offsets where the rig is Z-up.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.motion import Skeleton
from mocapqa.core.rig import ROLE_KEYS, ROLES, find_roles, limb_chains, role_key
from mocapqa.io.bvh import read_bvh

ARM = ROLES[:4]
LEG = ROLES[4:]


@dataclass(frozen=True)
class Convention:
    """A rig naming convention: ``{S}`` in a template is the side word."""

    sides: tuple[str, str]
    roles: dict[str, str]
    spine: dict[str, str] = field(default_factory=dict)
    hip_joint: str | None = None  # name of the joint between pelvis and thigh, else dropped
    above: dict[str, list[str]] = field(default_factory=dict)  # joints inserted above a role
    below: dict[str, list[str]] = field(default_factory=dict)  # joints inserted below a role
    leaves: dict[str, list[str]] = field(default_factory=dict)  # helper leaves under a role
    expected: dict[str, str] = field(default_factory=dict)  # role → joint, when not ``roles``
    missing: tuple[str, ...] = ()  # roles the convention has no joint for
    z_up: bool = False


CONVENTIONS: dict[str, Convention] = {
    # Xsens MVN BVH export: Collar is the clavicle, so Shoulder is the upper arm.
    "xsens_mvn": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG, ["{S}Collar", "{S}Shoulder", "{S}Elbow", "{S}Wrist",
                             "{S}Hip", "{S}Knee", "{S}Ankle", "{S}Toe"], strict=True)),
        spine={"LowerBack": "Chest", "Spine": "Chest2", "Spine1": "Chest3"},
    ),
    # Xsens MVN segment names (MVNX): Shoulder is the clavicle here.
    "xsens_segments": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG, ["{S}Shoulder", "{S}UpperArm", "{S}ForeArm", "{S}Hand",
                             "{S}UpperLeg", "{S}LowerLeg", "{S}Foot", "{S}Toe"], strict=True)),
        spine={"Hips": "Pelvis", "LowerBack": "L5", "Spine": "L3", "Spine1": "T8"},
    ),
    "perception_neuron": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG[:3], ["{S}Shoulder", "{S}Arm", "{S}ForeArm", "{S}Hand",
                                 "{S}UpLeg", "{S}Leg", "{S}Foot"], strict=True)),
        leaves={"hand": ["{S}HandThumb1", "{S}InHandIndex", "{S}InHandMiddle"]},
        missing=("toe",),
    ),
    "mixamo": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG, ["mixamorig7:{S}Shoulder", "mixamorig7:{S}Arm",
                             "mixamorig7:{S}ForeArm", "mixamorig7:{S}Hand", "mixamorig7:{S}UpLeg",
                             "mixamorig7:{S}Leg", "mixamorig7:{S}Foot", "mixamorig7:{S}ToeBase"],
                 strict=True)),
        spine={"Hips": "mixamorig7:Hips", "Spine": "mixamorig7:Spine"},
        leaves={"toe": ["mixamorig7:{S}Toe_End"], "hand": ["mixamorig7:{S}HandIndex1"]},
    ),
    "biped": Convention(
        ("L", "R"),
        dict(zip(ARM + LEG, ["Bip01 {S} Clavicle", "Bip01 {S} UpperArm", "Bip01 {S} Forearm",
                             "Bip01 {S} Hand", "Bip01 {S} Thigh", "Bip01 {S} Calf",
                             "Bip01 {S} Foot", "Bip01 {S} Toe0"], strict=True)),
        spine={"Hips": "Bip01 Pelvis", "Spine": "Bip01 Spine", "Head": "Bip01 Head"},
        leaves={"forearm": ["Bip01 {S} ForeTwist"], "hand": ["Bip01 {S} Finger0"],
                "toe": ["Bip01 {S} Toe0Nub"]},
    ),
    # MakeHuman classic: Hip_L sits between the pelvis and the thigh; __ bones are helpers.
    "makehuman_classic": Convention(
        ("L", "R"),
        dict(zip(ARM + LEG, ["Clavicle_{S}", "UpArm_{S}", "LoArm_{S}", "Hand_{S}", "UpLeg_{S}",
                             "LoLeg_{S}", "Foot_{S}", "Toe_{S}"], strict=True)),
        spine={"Hips": "Root", "LowerBack": "Spine1", "Spine": "Spine2", "Spine1": "Spine3"},
        hip_joint="Hip_{S}",
        above={"upper_arm": ["__UpArm_{S}"], "lower_leg": ["__LoLeg_{S}"]},
        leaves={"upper_arm": ["UpArmTwist_{S}"], "forearm": ["LoArmTwist_{S}"],
                "upper_leg": ["__UpLeg_{S}"]},
        z_up=True,
    ),
    # MakeHuman default skeleton: shoulder01 between clavicle and upper arm, two-bone segments.
    "makehuman_default": Convention(
        ("L", "R"),
        dict(zip(ARM + LEG, ["clavicle.{S}", "upperarm01.{S}", "lowerarm01.{S}", "wrist.{S}",
                             "upperleg01.{S}", "lowerleg01.{S}", "foot.{S}", "toe1-1.{S}"],
                 strict=True)),
        spine={"Hips": "root", "LowerBack": "spine05", "Spine": "spine04", "Spine1": "spine03"},
        hip_joint="pelvis.{S}",
        above={"upper_arm": ["shoulder01.{S}"]},
        below={"upper_arm": ["upperarm02.{S}"], "forearm": ["lowerarm02.{S}"],
               "upper_leg": ["upperleg02.{S}"], "lower_leg": ["lowerleg02.{S}"]},
        leaves={"hand": ["metacarpal1.{S}"]},
    ),
    # MakeHuman's MakeWalk "Default" target rig: a deltoid helper between shoulder and arm.
    "makehuman_makewalk": Convention(
        ("L", "R"),
        dict(zip(ARM + LEG, ["shoulder.{S}", "upper_arm.{S}", "forearm.{S}", "hand.{S}",
                             "thigh.{S}", "shin.{S}", "foot.{S}", "toe.{S}"], strict=True)),
        spine={"Hips": "hips", "LowerBack": "spine", "Spine": "spine-1", "Spine1": "chest"},
        above={"upper_arm": ["deltoid.{S}"]},
    ),
    "biovision": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG[:3], ["{S}Collar", "{S}UpArm", "{S}LowArm", "{S}Hand", "{S}UpLeg",
                                 "{S}LowLeg", "{S}Foot"], strict=True)),
        spine={"LowerBack": "Chest"},
        missing=("toe",),
    ),
    "humanik": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG, ["Character1_{S}Shoulder", "Character1_{S}Arm",
                             "Character1_{S}ForeArm", "Character1_{S}Hand",
                             "Character1_{S}UpLeg", "Character1_{S}Leg", "Character1_{S}Foot",
                             "Character1_{S}ToeBase"], strict=True)),
        spine={"Hips": "Character1_Hips", "Spine": "Character1_Spine"},
        leaves={"upper_arm": ["Character1_{S}ArmRoll"], "forearm": ["Character1_{S}ForeArmRoll"]},
    ),
    "rokoko": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG, ["{S}Shoulder", "{S}Arm", "{S}ForeArm", "{S}Hand", "{S}Thigh",
                             "{S}Shin", "{S}Foot", "{S}Toe"], strict=True)),
        spine={"LowerBack": "Spine1", "Spine": "Spine2", "Spine1": "Spine4"},
        leaves={"toe": ["{S}ToeTip"]},
    ),
    "unity_humanoid": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG, ["{S}Shoulder", "{S}UpperArm", "{S}LowerArm", "{S}Hand",
                             "{S}UpperLeg", "{S}LowerLeg", "{S}Foot", "{S}Toes"], strict=True)),
        spine={"LowerBack": "Spine", "Spine": "Chest", "Spine1": "UpperChest"},
    ),
    "unreal": Convention(
        ("l", "r"),
        dict(zip(ARM + LEG, ["clavicle_{S}", "upperarm_{S}", "lowerarm_{S}", "hand_{S}",
                             "thigh_{S}", "calf_{S}", "foot_{S}", "ball_{S}"], strict=True)),
        spine={"Hips": "pelvis", "LowerBack": "spine_01", "Spine": "spine_02"},
        leaves={"upper_arm": ["upperarm_twist_01_{S}"], "lower_leg": ["calf_twist_01_{S}"],
                "hand": ["index_01_{S}"]},
    ),
    # VRM humanoid (J_Bip_ prefix, side letter after it).
    "vrm": Convention(
        ("L", "R"),
        dict(zip(ARM + LEG, ["J_Bip_{S}_Shoulder", "J_Bip_{S}_UpperArm", "J_Bip_{S}_LowerArm",
                             "J_Bip_{S}_Hand", "J_Bip_{S}_UpperLeg", "J_Bip_{S}_LowerLeg",
                             "J_Bip_{S}_Foot", "J_Bip_{S}_ToeBase"], strict=True)),
        spine={"Hips": "J_Bip_C_Hips", "Spine": "J_Bip_C_Spine", "Head": "J_Bip_C_Head"},
    ),
    # SMPL: the wrist is the hand joint (left_hand is the end below it), the ankle the foot
    # (left_foot is the toe joint below it).
    "smpl": Convention(
        ("left", "right"),
        dict(zip(ARM + LEG, ["{S}_collar", "{S}_shoulder", "{S}_elbow", "{S}_wrist",
                             "{S}_hip", "{S}_knee", "{S}_ankle", "{S}_foot"], strict=True)),
        spine={"Hips": "pelvis", "LowerBack": "spine1", "Spine": "spine2", "Spine1": "spine3"},
        below={"hand": ["{S}_hand"]},
    ),
    "smpl_short": Convention(
        ("L", "R"),
        dict(zip(ARM + LEG, ["{S}_Collar", "{S}_Shoulder", "{S}_Elbow", "{S}_Wrist",
                             "{S}_Hip", "{S}_Knee", "{S}_Ankle", "{S}_Foot"], strict=True)),
        spine={"Hips": "Pelvis", "LowerBack": "Spine1", "Spine": "Spine2", "Spine1": "Spine3"},
        below={"hand": ["{S}_Hand"]},
    ),
    # Limbs named ...Leg → ...LowerLeg: "Leg" is the thigh here, not the shin (HumanIK).
    "leg_is_thigh": Convention(
        ("Left", "Right"),
        dict(zip(ARM + LEG[:3], ["{S}Shoulder", "{S}Arm", "{S}LowerArm", "{S}Hand", "{S}Leg",
                                 "{S}LowerLeg", "{S}Foot"], strict=True)),
        missing=("toe",),
    ),
    # No collar: Shoulder → Elbow → Wrist, so Shoulder is the upper arm.
    "shoulder_elbow_wrist": Convention(
        ("Left", "Right"),
        dict(zip(ARM[1:] + LEG, ["{S}Shoulder", "{S}Elbow", "{S}Wrist", "{S}Hip", "{S}Knee",
                                 "{S}Ankle", "{S}Toe"], strict=True)),
        missing=("clavicle",),
    ),
}  # fmt: skip


@dataclass
class Node:
    name: str
    offset: np.ndarray
    children: list[Node] = field(default_factory=list)


def source_tree(skeleton: Skeleton) -> tuple[Node, dict[str, Node]]:
    """The skeleton as a tree of nodes, with the role of each limb joint."""
    nodes = [Node(n, skeleton.offsets[j].copy()) for j, n in enumerate(skeleton.names)]
    for j, p in enumerate(skeleton.parents):
        if p >= 0:
            nodes[p].children.append(nodes[j])
    rig = find_roles(skeleton)
    assert rig.unmapped == ()
    return nodes[0], {key: nodes[j] for key, j in rig.roles.items()}


def drop(parent: Node, node: Node) -> None:
    """Remove ``node``, moving its children up (offsets composed)."""
    i = parent.children.index(node)
    for child in node.children:
        child.offset = child.offset + node.offset
    parent.children[i : i + 1] = node.children


def walk(root: Node) -> list[Node]:
    out, stack = [], [root]
    while stack:
        out.append(stack.pop())
        stack.extend(out[-1].children)
    return out


def parent_of(root: Node, node: Node) -> Node:
    stack = [root]
    while stack:
        here = stack.pop()
        if node in here.children:
            return here
        stack.extend(here.children)
    raise AssertionError(node.name)


def build(source: Skeleton, conv: Convention, rng: np.random.Generator) -> Skeleton:
    """The source skeleton renamed and restructured to the convention."""
    root, roles = source_tree(source)
    limb_nodes = set(map(id, roles.values()))
    for side, word in zip(("left", "right"), conv.sides, strict=True):
        fill = {"S": word}
        upper_leg = roles[role_key(side, "upper_leg")]
        hip = parent_of(root, upper_leg)
        if hip is not root and id(hip) not in limb_nodes:  # CMU's LHipJoint
            if conv.hip_joint:
                hip.name = conv.hip_joint.format_map(fill)
            else:
                drop(parent_of(root, hip), hip)
        hand = roles[role_key(side, "hand")]
        for finger in list(hand.children):  # fingers and thumbs of the source
            hand.children.remove(finger)
        for role in ROLES:
            node = roles[role_key(side, role)]
            if role in conv.missing:
                drop(parent_of(root, node), node)
                continue
            node.name = conv.roles[role].format_map(fill)
            for name in conv.above.get(role, []):
                parent = parent_of(root, node)
                extra = Node(name.format_map(fill), node.offset * 0.1, [node])
                node.offset = node.offset * 0.9
                parent.children[parent.children.index(node)] = extra
            for name in conv.below.get(role, []):
                extra = Node(name.format_map(fill), node.offset * 0.5, node.children)
                node.children = [extra]
            for name in conv.leaves.get(role, []):
                node.children.append(Node(name.format_map(fill), node.offset * 0.2))
    present = {n.name for n in walk(root)}
    spine = {k: v for k, v in conv.spine.items() if v not in present}
    names: list[str] = []
    parents: list[int] = []
    offsets: list[np.ndarray] = []
    stack: list[tuple[Node, int]] = [(root, -1)]
    while stack:
        node, parent = stack.pop()
        node.name = spine.get(node.name, node.name)
        names.append(node.name)
        parents.append(parent)
        offsets.append(node.offset[[0, 2, 1]] * [1, -1, 1] if conv.z_up else node.offset)
        here = len(names) - 1
        order = rng.permutation(len(node.children))
        stack.extend((node.children[k], here) for k in order)
    channels = tuple(("Zrotation", "Xrotation", "Yrotation") for _ in names)
    return Skeleton(tuple(names), np.array(parents), np.array(offsets), channels)


@pytest.fixture(scope="module")
def sources(corpus_dir: Path) -> list[Skeleton]:
    """The CMU walk and a seeded choice of three Bandai takes (two skeleton layouts)."""
    rng = np.random.default_rng(14)
    bandai = sorted((corpus_dir / "bvh" / "bandai").glob("*.bvh"))
    chosen = [bandai[int(i)] for i in rng.choice(len(bandai), size=3, replace=False)]
    paths = [corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh", *chosen]
    return [read_bvh(p).skeleton for p in paths]


@pytest.mark.parametrize("name", sorted(CONVENTIONS))
def test_every_convention_maps_its_roles(name: str, sources: list[Skeleton]) -> None:
    conv = CONVENTIONS[name]
    rng = np.random.default_rng(sum(map(ord, name)))
    for source in sources:
        for _ in range(3):  # three seeded child orders per source
            skeleton = build(source, conv, rng)
            rig = find_roles(skeleton)
            found = {key: skeleton.names[j] for key, j in rig.roles.items()}
            for side, word in zip(("left", "right"), conv.sides, strict=True):
                for role in ROLES:
                    key = role_key(side, role)
                    if role in conv.missing:
                        assert key not in found, f"{name}: {key} = {found.get(key)}"
                        continue
                    template = conv.expected.get(role, conv.roles[role])
                    assert found.get(key) == template.format(S=word), f"{name}: {key}"
            missing = {role_key(s, r) for s in ("left", "right") for r in conv.missing}
            assert set(rig.unmapped) == missing
            for joint in found.values():
                assert not joint.startswith("__")
            assert len(limb_chains(rig)) == 10 - 2 * sum(
                r in ("clavicle", "toe") for r in conv.missing
            )


def test_ambiguous_names_follow_the_structure(sources: list[Skeleton]) -> None:
    rng = np.random.default_rng(7)
    humanik_skeleton = build(sources[0], CONVENTIONS["humanik"], rng)
    humanik = find_roles(humanik_skeleton)
    xsens_skeleton = build(sources[0], CONVENTIONS["xsens_mvn"], rng)
    xsens = find_roles(xsens_skeleton)
    # "LeftShoulder": the clavicle above LeftArm, the upper arm below LeftCollar.
    assert humanik_skeleton.names[humanik.roles["left_clavicle"]] == "Character1_LeftShoulder"
    assert xsens_skeleton.names[xsens.roles["left_upper_arm"]] == "LeftShoulder"
    # "LeftLeg": the shin below LeftUpLeg, the thigh above LeftLowerLeg.
    thigh = build(sources[0], CONVENTIONS["leg_is_thigh"], rng)
    assert thigh.names[find_roles(thigh).roles["left_upper_leg"]] == "LeftLeg"
    neuron = build(sources[0], CONVENTIONS["perception_neuron"], rng)
    assert neuron.names[find_roles(neuron).roles["left_lower_leg"]] == "LeftLeg"


@pytest.mark.parametrize("prefix", ["mixamorig:", "mixamorig1:", "mixamorig12:", "mixamorig"])
def test_any_mixamo_prefix(prefix: str, sources: list[Skeleton]) -> None:
    conv = CONVENTIONS["mixamo"]
    renamed = Convention(
        conv.sides,
        {r: t.replace("mixamorig7:", prefix) for r, t in conv.roles.items()},
        leaves={"toe": [prefix + "{S}Toe_End"]},
    )
    skeleton = build(sources[0], renamed, np.random.default_rng(3))
    rig = find_roles(skeleton)
    assert rig.unmapped == ()
    assert skeleton.names[rig.roles["right_forearm"]] == prefix + "RightForeArm"


def test_a_mapping_in_either_orientation_overrides(sources: list[Skeleton]) -> None:
    skeleton = build(sources[0], CONVENTIONS["xsens_mvn"], np.random.default_rng(5))
    by_role = find_roles(skeleton, {"left_upper_arm": "LeftCollar", "left_clavicle": "Chest3"})
    by_joint = find_roles(skeleton, {"LeftCollar": "left_upper_arm", "Chest3": "left_clavicle"})
    assert by_role == by_joint
    assert skeleton.names[by_role.roles["left_upper_arm"]] == "LeftCollar"
    assert set(ROLE_KEYS) - set(by_role.roles) == set()
