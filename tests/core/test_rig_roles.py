"""Rig roles on every rig of the corpus and on synthetic Mixamo and Unreal skeletons."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.motion import Skeleton
from mocapqa.core.rig import ROLES, SIDES, find_roles, limb_chains, role_key, split_side
from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh

ALL_ROLE_KEYS = {role_key(side, role) for side in SIDES for role in ROLES}

# Left-side joint per role, from each rig family's naming convention (right mirrors left).
EXPECTED_LEFT = {
    "cmu": {
        "clavicle": "LeftShoulder", "upper_arm": "LeftArm", "forearm": "LeftForeArm",
        "hand": "LeftHand", "upper_leg": "LeftUpLeg", "lower_leg": "LeftLeg",
        "foot": "LeftFoot", "toe": "LeftToeBase",
    },
    "iclone": {
        "clavicle": "CC_Base_L_Clavicle", "upper_arm": "CC_Base_L_Upperarm",
        "forearm": "CC_Base_L_Forearm", "hand": "CC_Base_L_Hand", "upper_leg": "CC_Base_L_Thigh",
        "lower_leg": "CC_Base_L_Calf", "foot": "CC_Base_L_Foot", "toe": "CC_Base_L_ToeBase",
    },
    "bandai": {
        "clavicle": "Shoulder_L", "upper_arm": "UpperArm_L", "forearm": "LowerArm_L",
        "hand": "Hand_L", "upper_leg": "UpperLeg_L", "lower_leg": "LowerLeg_L",
        "foot": "Foot_L", "toe": "Toes_L",
    },
    # Classic BVH: Collar is the clavicle, so Shoulder is the upper arm.
    "bvh_test2": {
        "clavicle": "LeftCollar", "upper_arm": "LeftShoulder", "forearm": "LeftElbow",
        "hand": "LeftWrist", "upper_leg": "LeftHip", "lower_leg": "LeftKnee",
        "foot": "LeftAnkle", "toe": "LeftToe",
    },
}  # fmt: skip


def family(path: Path) -> str:
    if "iclone" in path.parts:
        return "iclone"
    if "bandai" in path.parts:
        return "bandai"
    if path.stem == "bvh_test2":
        return "bvh_test2"
    return "cmu"  # the CMU walk and the CMU-named misc takes (LeftArm, LeftUpLeg, ...)


def mirrored(name: str) -> str:
    for left, right in (("Left", "Right"), ("_L_", "_R_"), ("_L", "_R")):
        if left in name:
            return name.replace(left, right)
    raise AssertionError(name)


def test_every_corpus_rig_maps_all_limb_roles(bvh_files: list[Path]) -> None:
    rigs: dict[tuple[str, ...], Path] = {}
    for path in bvh_files:
        skeleton = read_bvh(path).skeleton
        rigs.setdefault(skeleton.names, path)
    assert len(rigs) >= 6  # CMU, two iClone exports, Bandai, PyMO, pybvh samples
    for names, path in rigs.items():
        skeleton = read_bvh(path).skeleton
        rig = find_roles(skeleton)
        assert rig.unmapped == (), f"{path.name}: unmapped {rig.unmapped}"
        assert set(rig.roles) == ALL_ROLE_KEYS
        found = {key: names[j] for key, j in rig.roles.items()}
        if path.stem in ("bvh_test3",):
            assert found["left_toe"] == "LeftForeFoot"  # its toe joint is named ForeFoot
        else:
            for role, joint in EXPECTED_LEFT[family(path)].items():
                assert found[role_key("left", role)] == joint, path.name
                assert found[role_key("right", role)] == mirrored(joint), path.name
        # Helper bones never take a role.
        for joint in found.values():
            assert not any(h in joint.lower() for h in ("twist", "share", "thumb", "index"))
        assert len(limb_chains(rig)) == 10


def chain_skeleton(edges: list[tuple[str, str | None]]) -> Skeleton:
    """A skeleton from (joint, parent) pairs in depth-first order, with unit offsets."""
    names = tuple(name for name, _ in edges)
    parents = np.array([names.index(p) if p else -1 for _, p in edges])
    channels = tuple(("Zrotation", "Xrotation", "Yrotation") for _ in names)
    return Skeleton(names, parents, np.ones((len(names), 3)), channels)


def limb(prefix: str, names: list[str], parent: str) -> list[tuple[str, str | None]]:
    edges: list[tuple[str, str | None]] = []
    for name in names:
        edges.append((prefix + name, parent))
        parent = prefix + name
    return edges


def mixamo_skeleton() -> Skeleton:
    p = "mixamorig:"
    edges: list[tuple[str, str | None]] = [(p + "Hips", None), (p + "Spine", p + "Hips")]
    for side in ("Left", "Right"):
        arm = ["Shoulder", "Arm", "ForeArm", "Hand", "HandIndex1", "HandIndex2"]
        edges += limb(p, [side + n for n in arm], p + "Spine")
        leg = ["UpLeg", "Leg", "Foot", "ToeBase", "Toe_End"]
        edges += limb(p, [side + n for n in leg], p + "Hips")
    return chain_skeleton(edges)


def unreal_skeleton() -> Skeleton:
    edges: list[tuple[str, str | None]] = [("root", None), ("pelvis", "root")]
    edges.append(("spine_01", "pelvis"))
    for s in ("l", "r"):
        edges += [
            (f"clavicle_{s}", "spine_01"), (f"upperarm_{s}", f"clavicle_{s}"),
            (f"upperarm_twist_01_{s}", f"upperarm_{s}"), (f"lowerarm_{s}", f"upperarm_{s}"),
            (f"lowerarm_twist_01_{s}", f"lowerarm_{s}"), (f"hand_{s}", f"lowerarm_{s}"),
            (f"index_01_{s}", f"hand_{s}"), (f"thigh_{s}", "pelvis"),
            (f"thigh_twist_01_{s}", f"thigh_{s}"), (f"calf_{s}", f"thigh_{s}"),
            (f"calf_twist_01_{s}", f"calf_{s}"), (f"foot_{s}", f"calf_{s}"),
            (f"ball_{s}", f"foot_{s}"),
        ]  # fmt: skip
    return chain_skeleton(edges)


def test_mixamo_names_map_to_roles() -> None:
    skeleton = mixamo_skeleton()
    rig = find_roles(skeleton)
    assert rig.unmapped == ()
    names = {key: skeleton.names[j] for key, j in rig.roles.items()}
    assert names["left_clavicle"] == "mixamorig:LeftShoulder"
    assert names["left_upper_arm"] == "mixamorig:LeftArm"
    assert names["right_forearm"] == "mixamorig:RightForeArm"
    assert names["left_hand"] == "mixamorig:LeftHand"
    assert names["right_toe"] == "mixamorig:RightToeBase"
    assert split_side("mixamorig:LeftArm") == ("left", "arm")


def test_unreal_names_map_to_roles_and_skip_twist_bones() -> None:
    skeleton = unreal_skeleton()
    rig = find_roles(skeleton)
    assert rig.unmapped == ()
    names = {key: skeleton.names[j] for key, j in rig.roles.items()}
    assert names["left_upper_arm"] == "upperarm_l"
    assert names["left_forearm"] == "lowerarm_l"
    assert names["right_upper_leg"] == "thigh_r"
    assert names["right_lower_leg"] == "calf_r"
    assert names["left_toe"] == "ball_l"
    assert "upperarm_twist_01_l" not in names.values()
    chains = {(c.side, c.segment): c for c in limb_chains(rig)}
    upper_arm = chains[("left", "upper_arm")]
    assert skeleton.names[upper_arm.child] == "lowerarm_l"
    assert upper_arm.grandchild is not None
    assert skeleton.names[upper_arm.grandchild] == "hand_l"


def test_missing_joints_are_reported_unmapped_and_their_chains_dropped() -> None:
    edges: list[tuple[str, str | None]] = [("Hips", None)]
    edges += limb("", ["LeftUpLeg", "LeftLeg", "LeftFoot"], "Hips")
    edges += limb("", ["RightUpLeg", "RightLeg"], "Hips")
    skeleton = chain_skeleton(edges)
    rig = find_roles(skeleton)
    assert set(rig.unmapped) == ALL_ROLE_KEYS - {
        "left_upper_leg", "left_lower_leg", "left_foot", "right_upper_leg", "right_lower_leg",
    }  # fmt: skip
    chains = [(c.side, c.segment) for c in limb_chains(rig)]
    assert chains == [("left", "upper_leg")]


def test_a_mapping_overrides_the_guess() -> None:
    skeleton = unreal_skeleton()
    rig = find_roles(skeleton, {"upperarm_twist_01_l": "left_upper_arm"})
    assert skeleton.names[rig.roles["left_upper_arm"]] == "upperarm_twist_01_l"


@pytest.mark.parametrize(
    ("mapping", "pattern"),
    [
        ({"upperarm_l": "left_elbow"}, r"Expected a role in .*got 'upperarm_l': 'left_elbow'"),
        ({"no_such_joint": "left_hand"}, r"left_hand to be a joint of this skeleton, got 'no_such"),
        # Each of these was read without a word: one role kept, the other dropped.
        (
            {"left_upper_arm": "upperarm_l", "right_upper_arm": "upperarm_l"},
            r"one role per joint, got 'upperarm_l' for left_upper_arm and right_upper_arm",
        ),
        (
            {"left_upper_arm": "hand_l", "left_forearm": "upperarm_l"},
            r"left_forearm \('upperarm_l'\) below the left_upper_arm \('hand_l'\)",
        ),
        ({"left_upper_arm": "pelvis"}, r"below the left_clavicle .*\(map left_clavicle too\)"),
    ],
)
def test_a_bad_mapping_is_an_input_error(mapping: dict[str, str], pattern: str) -> None:
    with pytest.raises(InputError, match=pattern):
        find_roles(unreal_skeleton(), mapping)


def test_a_joint_the_mapping_gives_a_role_loses_the_role_found_by_name() -> None:
    skeleton = unreal_skeleton()
    # lowerarm_l is the forearm by name; mapped as the hand, it is the hand only (before, both
    # roles held it, and the hand, not below itself, was dropped without a word).
    rig = find_roles(skeleton, {"left_hand": "lowerarm_l"})
    assert rig.roles["left_hand"] == skeleton.index("lowerarm_l")
    assert "left_forearm" in rig.unmapped
    assert rig.roles["left_upper_arm"] == skeleton.index("upperarm_l")
