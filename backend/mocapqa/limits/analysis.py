"""Check a take against a limits model: validity and a soft score per frame and joint.

The lookup map decides validity (the fast path); the score is the distance outside the valid
region, ``√(swing_deg² + twist_deg²)``, so violations can be ranked, not only flagged (see
:func:`mocapqa.limits.occupancy.limit_distances`). The discriminator can be asked instead of the
map with ``method="network"``; the score always comes from the map. With a canonical model
the take's role joints are charted in their anatomical frames (:mod:`mocapqa.limits.canonical`),
so any rig with roles is checked; the report lists the joints it does not check and reads each
violation out in anatomical terms (:mod:`mocapqa.limits.readout`). The JSON forms are
documented in ``docs/limits.md``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles
from mocapqa.errors import InputError, LimitsFileError
from mocapqa.kinematics.quaternion import multiply
from mocapqa.limits.canonical import (
    CANONICAL_AXIS,
    STAND_IN_PARENTS,
    CanonicalFrames,
    rig_key,
    stand_in_roles,
    take_frames,
)
from mocapqa.limits.charting import canonical_params
from mocapqa.limits.discriminator import network_valid
from mocapqa.limits.expmap import limit_params_from_quats
from mocapqa.limits.model import LimitsModel, check_rig
from mocapqa.limits.occupancy import evaluate
from mocapqa.limits.readout import violation_text
from mocapqa.limits.storage import load_default_model

__all__ = ["LimitsReport", "charted", "check_limits", "joint_map_json", "limit_params"]

_WORST = 5


@dataclass(frozen=True, slots=True)
class LimitsReport:
    """Per frame × joint validity and scores of one take.

    Parameters
    ----------
    joint_names : tuple of str
        The model's joints, in model order (J).
    roles : tuple of str
        Their role keys.
    params_deg : ndarray, shape (F, J, 3)
        ``(s1, s2, τ)`` in degrees.
    valid : ndarray of bool, shape (F, J)
    score_deg : ndarray, shape (F, J)
        Distance outside the valid region (0 when valid by the map).
    swing_deg, twist_deg : ndarray, shape (F, J)
        The swing and twist parts of the score.
    fps : float
    rig_family : str
    method : {"map", "network"}
    excess_deg : ndarray, shape (F, J, 3)
        Signed excess of ``(s1, s2, τ)`` beyond the limits (0 inside), for the read-out.
    not_checked : tuple of str
        The take's joints this check does not cover (no role, or a role the model lacks),
        and the model's roles missing from the take.
    framing : str
        How the take's joints were read: by the rig's own model, in the rig's stored
        canonical frames, or in frames estimated from the take (and how many frames inside
        twist intervals were left out of that estimate).
    """

    joint_names: tuple[str, ...]
    roles: tuple[str, ...]
    params_deg: FloatArray
    valid: BoolArray
    score_deg: FloatArray
    swing_deg: FloatArray
    twist_deg: FloatArray
    fps: float
    rig_family: str
    method: str
    excess_deg: FloatArray
    not_checked: tuple[str, ...] = ()
    framing: str = ""

    def readout(self, frame: int, joint: int) -> str:
        """Anatomical read-out of one frame and joint ("right knee hyperextended 14°").

        Empty when the frame is valid or the joint has no role.
        """
        if self.valid[frame, joint]:
            return ""
        return violation_text(self.roles[joint], self.excess_deg[frame, joint].tolist())

    @property
    def flagged_fraction(self) -> float:
        """Share of frame × joints outside the limits."""
        return float(1.0 - self.valid.mean()) if self.valid.size else 0.0

    def to_json(self, max_points: int | None = None) -> dict[str, Any]:
        """A JSON-ready summary (layout in ``docs/limits.md``).

        Parameters
        ----------
        max_points : int, optional
            At most this many frames per joint in the ``frames`` series (evenly strided); None
            keeps every frame.
        """
        n = self.valid.shape[0]
        step = 1 if max_points is None or n <= max_points else int(np.ceil(n / max(max_points, 1)))
        frames = np.arange(0, n, step)
        joints = []
        for j, name in enumerate(self.joint_names):
            order = np.argsort(-self.score_deg[:, j], kind="stable")
            worst = [int(f) for f in order[:_WORST] if not self.valid[f, j]]
            joints.append(
                {
                    "name": name,
                    "role": self.roles[j],
                    "flagged_fraction": float(1.0 - self.valid[:, j].mean()) if n else 0.0,
                    "max_score_deg": float(self.score_deg[:, j].max()) if n else 0.0,
                    "readout": self.readout(int(order[0]), j) if n else "",
                    "worst_frames": [
                        {
                            "frame": f,
                            "s1_deg": round(float(self.params_deg[f, j, 0]), 3),
                            "s2_deg": round(float(self.params_deg[f, j, 1]), 3),
                            "tau_deg": round(float(self.params_deg[f, j, 2]), 3),
                            "score_deg": round(float(self.score_deg[f, j]), 3),
                            "swing_deg": round(float(self.swing_deg[f, j]), 3),
                            "twist_deg": round(float(self.twist_deg[f, j]), 3),
                            "readout": self.readout(f, j),
                        }
                        for f in worst
                    ],
                    "frames": {
                        "frame": frames.tolist(),
                        "valid": self.valid[frames, j].tolist(),
                        "score_deg": np.round(self.score_deg[frames, j], 3).tolist(),
                    },
                }
            )
        return {
            "rig_family": self.rig_family,
            "method": self.method,
            "fps": self.fps,
            "n_frames": n,
            "flagged_fraction": self.flagged_fraction,
            "joints": joints,
            "not_checked": list(self.not_checked),
            "framing": self.framing,
        }


def charted(
    motion: Motion,
    model: LimitsModel,
    mapping: Mapping[str, str] | None = None,
    ignore: BoolArray | None = None,
) -> tuple[FloatArray, list[int], tuple[str, ...], tuple[str, ...]]:
    """``(s1, s2, τ)`` of the model's joints found on the take, and what is not checked.

    Parameters
    ----------
    motion : Motion
    model : LimitsModel
    mapping : mapping, optional
        Role key → joint name overriding the roles found (canonical models only; the take's
        frames are then estimated from the take, not taken from the model).
    ignore : ndarray of bool, shape (F, J), optional
        Frames of each joint inside a twist interval found on the take: when the take's
        canonical frames are estimated from the take itself, those frames do not set them
        (:func:`mocapqa.limits.canonical.canonical_frames`).

    Returns
    -------
    params : ndarray, shape (F, K, 3)
        Radians, for the K model joints present on the take.
    columns : list of int
        Index into ``model.joints`` of each of the K columns.
    not_checked : tuple of str
        Joint names of the take outside the check, then model roles missing from the take.
    names : tuple of str
        The take's joint name of each of the K columns.

    Raises
    ------
    LimitsFileError
        If the model does not cover the take's rig.
    """
    check_rig(model, motion.skeleton, mapping)
    if model.frame != "canonical":
        return _charted_by_name(motion, model)
    try:
        if mapping:
            frames = take_frames(motion, rig=find_roles(motion.skeleton, mapping), ignore=ignore)
        else:
            frames = take_frames(motion, known=_known_frames(motion, model), ignore=ignore)
    except InputError as e:
        raise LimitsFileError(f"Expected a skeleton the canonical frames apply to: {e}") from e
    column = {role: k for k, role in enumerate(frames.roles)}
    columns = [k for k, j in enumerate(model.joints) if j.role in column]
    picked = [column[model.joints[k].role] for k in columns]
    references = _references(model, columns, frames.stand_ins)
    # conj(reference) ⊗ conj(A_parent) ⊗ A_child = conj(A_parent ⊗ reference) ⊗ A_child: the
    # reference joins the parent's constant frame, saving one product per frame.
    charted_frames = replace(
        frames,
        roles=tuple(frames.roles[c] for c in picked),
        joints=frames.joints[picked],
        parents=frames.parents[picked],
        frames=frames.frames[picked],
        parent_frames=multiply(frames.parent_frames[picked], references),
    )
    params = canonical_params(motion, charted_frames, CANONICAL_AXIS)
    used = {int(frames.joints[c]) for c in picked}
    unused = [n for i, n in enumerate(motion.skeleton.names) if i not in used]
    missing = [j.role for j in model.joints if j.role not in column]
    names = tuple(motion.skeleton.names[int(frames.joints[c])] for c in picked)
    return params, columns, tuple(unused + missing), names


def _charted_by_name(
    motion: Motion, model: LimitsModel
) -> tuple[FloatArray, list[int], tuple[str, ...], tuple[str, ...]]:
    """:func:`charted` with a per-rig model, whose joints are matched by name."""
    index = [motion.skeleton.index(j.name) for j in model.joints]
    axes = np.stack([j.axis for j in model.joints])
    references = np.stack([j.reference for j in model.joints])
    params = limit_params_from_quats(motion.quats[:, index], axes, references)
    modelled = {j.name for j in model.joints}
    rest = tuple(n for n in motion.skeleton.names if n not in modelled)
    return params, list(range(len(model.joints))), rest, tuple(j.name for j in model.joints)


def _references(model: LimitsModel, columns: list[int], stand_ins: tuple[str, ...]) -> FloatArray:
    """The reference rotation of each of the model's joints ``columns``, shape (K, 4): a role
    in ``stand_ins``, whose parent role (an upper arm's clavicle) is missing, has it stand at
    the model's mean pose of that role relative to the body: conj(A_body ⊗ ref_parent) ⊗
    A_child."""
    references = np.stack([model.joints[k].reference for k in columns])
    by_role = {j.role: j for j in model.joints}
    for c, k in enumerate(columns):
        role = model.joints[k].role
        side, _, own = role.partition("_")
        stand_in = by_role.get(f"{side}_{STAND_IN_PARENTS.get(own, '')}")
        if role in stand_ins and stand_in is not None:
            references[c] = multiply(stand_in.reference, references[c])
    return references


def _known_frames(motion: Motion, model: LimitsModel) -> CanonicalFrames | None:
    """The model's stored frames of this take's rig, or None for a rig it has not seen."""
    stored = model.rig_frames.get(rig_key(motion))
    if stored is None:
        return None
    skeleton = motion.skeleton
    try:
        joints = np.array([skeleton.index(n) for n in stored.joints], dtype=np.intp)
        parents = np.array([skeleton.index(n) for n in stored.parents], dtype=np.intp)
    except KeyError:
        return None
    missing = tuple(j.role for j in model.joints if j.role not in stored.roles)
    return CanonicalFrames(
        stored.roles, joints, parents, stored.frames, stored.parent_frames, missing,
        stand_in_roles(stored.roles),
    )  # fmt: skip


def limit_params(motion: Motion, model: LimitsModel) -> FloatArray:
    """``(s1, s2, τ)`` in radians of the model's joints found on ``motion``, shape (F, K, 3).

    Raises
    ------
    LimitsFileError
        If the model does not cover the take's rig.
    """
    return charted(motion, model)[0]


def check_limits(
    motion: Motion,
    model: LimitsModel | None = None,
    method: str = "map",
    mapping: Mapping[str, str] | None = None,
    ignore: BoolArray | None = None,
) -> LimitsReport:
    """Check every frame of a take against joint limits.

    Parameters
    ----------
    motion : Motion
    model : LimitsModel, optional
        Defaults to the shipped model covering the take's rig.
    method : {"map", "network"}
        Who decides validity: the lookup map or the discriminator.
    mapping : mapping, optional
        Role key → joint name overriding the roles found; with a canonical model it decides
        which joints are checked (a per-rig model matches joints by name and ignores it).
    ignore : ndarray of bool, shape (F, J), optional
        Frames inside the take's twist intervals, per joint (:func:`charted`): they are still
        checked, but do not set the frames a take of an unknown rig is read in.

    Returns
    -------
    LimitsReport

    Raises
    ------
    LimitsFileError
        If no model covers the rig, or ``method="network"`` and the model has no networks.
    InputError
        On an unknown ``method``.
    """
    if method not in ("map", "network"):
        raise InputError(f"Expected `method` 'map' or 'network', got {method!r}")
    if model is None:
        model = load_default_model(motion.skeleton, mapping)
    params, columns, not_checked, names = charted(motion, model, mapping, ignore)
    n_frames, n_joints = params.shape[:2]
    swing = np.zeros((n_frames, n_joints))
    twist = np.zeros((n_frames, n_joints))
    excess = np.zeros((n_frames, n_joints, 3))
    valid = np.zeros((n_frames, n_joints), dtype=bool)
    joints = [model.joints[k] for k in columns]
    for j, joint in enumerate(joints):
        valid[:, j], swing[:, j], twist[:, j], excess[:, j] = evaluate(
            joint.occupancy, params[:, j]
        )
        if method == "network":
            if joint.network is None:
                raise LimitsFileError(
                    f"Expected a discriminator for joint {joint.name!r}, got none"
                )
            valid[:, j] = network_valid(joint.network, params[:, j])
    # The map's distances and excess are already 0 wherever the map finds a frame valid.
    score = np.hypot(swing, twist)
    if method == "network":
        excess = np.where(valid[..., None], 0.0, excess)
    return LimitsReport(
        joint_names=names,
        roles=tuple(j.role for j in joints),
        params_deg=np.rad2deg(params),
        valid=valid,
        score_deg=score,
        swing_deg=swing,
        twist_deg=twist,
        fps=motion.fps,
        rig_family=model.rig_family,
        method=method,
        excess_deg=excess,
        not_checked=not_checked,
        framing=_framing(motion, model, mapping, ignore),
    )


def _framing(
    motion: Motion, model: LimitsModel, mapping: Mapping[str, str] | None, ignore: BoolArray | None
) -> str:
    """How :func:`charted` read the take (:attr:`LimitsReport.framing`)."""
    if model.frame != "canonical":
        return "the rig's own model"
    if not mapping and _known_frames(motion, model) is not None:
        return "canonical frames stored for this rig"
    left_out = 0 if ignore is None else int(ignore.any(axis=1).sum())
    extra = f", {left_out} frame(s) inside twist intervals left out" if left_out else ""
    return f"canonical frames estimated from this take{extra}"


def joint_map_json(model: LimitsModel, joint: str) -> dict[str, Any]:
    """The lookup map of one joint for plotting (layout in ``docs/limits.md``).

    Parameters
    ----------
    model : LimitsModel
    joint : str
        Joint name or role key.

    Raises
    ------
    LimitsFileError
        If the model has no such joint.
    """
    limits = model.joint(joint)
    occupancy = limits.occupancy
    n = occupancy.n_bins
    centres = -180.0 + (np.arange(n) + 0.5) * occupancy.bin_deg
    i1, i2 = np.nonzero(occupancy.occupied)
    return {
        "name": limits.name,
        "role": limits.role,
        "rig_family": model.rig_family,
        "bin_deg": occupancy.bin_deg,
        "n_bins": n,
        "bin_centres_deg": centres.tolist(),
        "occupied_bins": {
            "i1": i1.tolist(),
            "i2": i2.tolist(),
            "s1_deg": centres[i1].tolist(),
            "s2_deg": centres[i2].tolist(),
            "tau_min_deg": np.round(np.rad2deg(occupancy.tau_min[i1, i2]), 3).tolist(),
            "tau_max_deg": np.round(np.rad2deg(occupancy.tau_max[i1, i2]), 3).tolist(),
        },
        "scores": None
        if limits.scores is None
        else {
            "accuracy": limits.scores.accuracy,
            "precision": limits.scores.precision,
            "recall": limits.scores.recall,
        },
    }
