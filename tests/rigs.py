"""Re-rigged copies of real takes: the same world motion with other joint frames and names."""

from __future__ import annotations

import numpy as np

from mocapqa.core.motion import EndSite, Motion, Skeleton
from mocapqa.kinematics.quaternion import conjugate, multiply, rotate

# CMU names → Bandai-style names for the role joints (a renamed rig).
RENAMES = {
    "LeftShoulder": "Shoulder_L", "LeftArm": "UpperArm_L", "LeftForeArm": "LowerArm_L",
    "LeftHand": "Hand_L", "LeftUpLeg": "UpperLeg_L", "LeftLeg": "LowerLeg_L",
    "LeftFoot": "Foot_L", "LeftToeBase": "Toes_L", "RightShoulder": "Shoulder_R",
    "RightArm": "UpperArm_R", "RightForeArm": "LowerArm_R", "RightHand": "Hand_R",
    "RightUpLeg": "UpperLeg_R", "RightLeg": "LowerLeg_R", "RightFoot": "Foot_R",
    "RightToeBase": "Toes_R",
}  # fmt: skip


def rerig(motion: Motion, seed: int, renames: dict[str, str] | None = None) -> Motion:
    """The same world motion on a rig whose every joint frame is turned by a random rotation.

    ``q'_j = conj(G_parent) ⊗ q_j ⊗ G_j``, OFFSETs re-expressed in the turned parent frames,
    End Sites in the turned joint frames; position channels of non-root joints are turned too.
    """
    skeleton = motion.skeleton
    rng = np.random.default_rng(seed)
    turns = rng.normal(size=(skeleton.n_joints, 4))
    turns /= np.linalg.norm(turns, axis=1, keepdims=True)
    identity = np.array([0.0, 0.0, 0.0, 1.0])
    parent_turns = np.stack([turns[p] if p >= 0 else identity for p in skeleton.parents.tolist()])
    quats = multiply(multiply(conjugate(parent_turns)[None], motion.quats), turns[None])
    offsets = rotate(conjugate(parent_turns), skeleton.offsets)
    translations = motion.translations.copy()
    for j in range(skeleton.n_joints):
        if skeleton.parents[j] >= 0 and any(c.endswith("position") for c in skeleton.channels[j]):
            translations[:, j] = rotate(conjugate(parent_turns[j])[None], translations[:, j])
    end_sites = tuple(
        EndSite(e.parent, tuple(rotate(conjugate(turns[e.parent]), np.asarray(e.offset))))  # type: ignore[arg-type]
        for e in skeleton.end_sites
    )
    names = tuple((renames or {}).get(n, n) for n in skeleton.names)
    turned = Skeleton(
        names=names,
        parents=skeleton.parents,
        offsets=offsets,
        channels=skeleton.channels,
        end_sites=end_sites,
        length_unit=skeleton.length_unit,
        root_translation=skeleton.root_translation,
    )
    return Motion(turned, quats, translations, motion.fps)


def roll_joint(motion: Motion, joint: int, degrees: float, frames: slice) -> Motion:
    """``motion`` with ``joint`` rolled by ``degrees`` about its bone (its first child's
    OFFSET) on ``frames``, every child undoing the roll: a twist error whose children keep
    their world poses."""
    child = motion.skeleton.children(joint)[0]
    axis = motion.skeleton.offsets[child] / np.linalg.norm(motion.skeleton.offsets[child])
    half = np.deg2rad(degrees) / 2
    turn = np.r_[np.sin(half) * axis, np.cos(half)]
    quats = motion.quats.copy()
    quats[frames, joint] = multiply(quats[frames, joint], turn)
    for c in motion.skeleton.children(joint):
        quats[frames, c] = multiply(conjugate(turn), quats[frames, c])
    return Motion(motion.skeleton, quats, motion.translations, motion.fps)
