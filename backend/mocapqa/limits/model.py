"""Limits models: the per-joint maps and networks of one rig family, and which rig they fit.

The file format and the shipped models are in :mod:`mocapqa.limits.storage`.

A per-rig model (``frame == "rig"``) applies to a skeleton only when the skeleton matches its
fingerprint (:mod:`mocapqa.limits.rig`); :func:`check_rig` refuses any other rig. A canonical
model (``frame == "canonical"``, :mod:`mocapqa.limits.canonical`) applies to any skeleton with
limb roles; it also stores the canonical frames of the rigs it was built from (``"rigs"`` in
``meta``, arrays ``rig{i}/frames`` and ``rig{i}/parent_frames``).
:func:`mocapqa.limits.storage.load_default_model` picks the canonical model except for the
rigs in :data:`mocapqa.limits.storage.PREFERRED_RIG_MODELS`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from mocapqa import __version__
from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Skeleton
from mocapqa.errors import LimitsFileError
from mocapqa.limits.discriminator import DiscriminatorScores, Network
from mocapqa.limits.occupancy import OccupancyMap, OccupancyParams
from mocapqa.limits.rig import fingerprint_mismatches, rig_family, rig_fingerprint

__all__ = ["JointLimits", "LimitsModel", "StoredFrames", "check_rig"]


@dataclass(frozen=True, slots=True)
class JointLimits:
    """The limits of one joint.

    Parameters
    ----------
    role : str
        Role key, e.g. ``"left_upper_arm"``.
    name : str
        Joint name on the rig.
    axis : ndarray, shape (3,)
        Unit bone (twist) axis in the joint's frame.
    reference : ndarray, shape (4,)
        Reference rotation (mean pose) the parameters are taken relative to.
    occupancy : OccupancyMap
    network : Network or None
        The discriminator, when one was trained.
    scores : DiscriminatorScores or None
        Its held-out synthetic test scores.
    n_samples : int
        Corpus frames the map was built from.
    """

    role: str
    name: str
    axis: FloatArray
    reference: FloatArray
    occupancy: OccupancyMap
    network: Network | None
    scores: DiscriminatorScores | None
    n_samples: int


@dataclass(frozen=True, slots=True)
class StoredFrames:
    """Canonical frames of one rig a canonical model was built from.

    Parameters
    ----------
    family : str
        Readable rig label.
    roles : tuple of str
        Role keys.
    joints, parents : tuple of str
        Joint name per role, and the joint whose frame it is relative to.
    frames, parent_frames : ndarray, shape (R, 4)
        See :class:`mocapqa.limits.canonical.CanonicalFrames`.
    """

    family: str
    roles: tuple[str, ...]
    joints: tuple[str, ...]
    parents: tuple[str, ...]
    frames: FloatArray
    parent_frames: FloatArray


@dataclass(frozen=True, slots=True)
class LimitsModel:
    """Learned joint limits for one rig family.

    Parameters
    ----------
    rig_family : str
        Readable family label (``"cmu"``, ``"character_creator"``, ``"bandai"``).
    fingerprint : dict
        Role key → (joint name, bone-axis label) that a skeleton must match.
    joints : tuple of JointLimits
    occupancy_params : OccupancyParams
        The map settings the model was built with.
    reference : str
        ``"mean"`` or ``"identity"``: how the per-joint reference rotations were chosen.
    corpus_hash : str
        sha256 of the build takes' names and modelled rotations.
    takes : tuple of str
        Names of the build takes.
    n_frames : int
        Frames in the build corpus.
    version : str
        mocapqa version that built the model.
    frame : {"rig", "canonical"}
        "rig": rotations in the rig's own joint frames (one rig, checked by fingerprint);
        "canonical": rotations in the anatomical frames of :mod:`mocapqa.limits.canonical`,
        so the model applies to any skeleton with roles.
    rig_frames : dict
        Canonical models only: :func:`mocapqa.limits.canonical.rig_key` → the
        :class:`StoredFrames` of each rig the model was built from.
    """

    rig_family: str
    fingerprint: dict[str, tuple[str, str]]
    joints: tuple[JointLimits, ...]
    occupancy_params: OccupancyParams
    reference: str
    corpus_hash: str
    takes: tuple[str, ...]
    n_frames: int
    version: str = __version__
    frame: str = "rig"
    rig_frames: dict[str, StoredFrames] = field(default_factory=dict)

    def joint(self, name_or_role: str) -> JointLimits:
        """The joint with this name or role key.

        Raises
        ------
        LimitsFileError
            If the model has no such joint.
        """
        for joint in self.joints:
            if name_or_role in (joint.name, joint.role):
                return joint
        names = [j.name for j in self.joints]
        raise LimitsFileError(f"Expected a joint of the model {names}, got {name_or_role!r}")


def check_rig(
    model: LimitsModel, skeleton: Skeleton, mapping: Mapping[str, str] | None = None
) -> None:
    """Raise LimitsFileError unless ``model`` applies to ``skeleton`` (a canonical model to any
    skeleton with limb roles, found by name or named by ``mapping``; a per-rig model to its
    rig's joint names).

    Raises
    ------
    LimitsFileError
        Naming the model's rig family, the skeleton's and the first differences.
    """
    if model.frame == "canonical":
        if not rig_fingerprint(skeleton, mapping):
            raise LimitsFileError(
                f"Expected a skeleton with limb roles for the canonical limits model, got none "
                f"among {list(skeleton.names[:6])}; name them with a mapping (docs/rigs.md)"
            )
        return
    problems = fingerprint_mismatches(model.fingerprint, skeleton)
    if problems:
        shown = "; ".join(problems[:3]) + (
            f"; and {len(problems) - 3} more" if len(problems) > 3 else ""
        )
        raise LimitsFileError(
            f"Expected a skeleton of the {model.rig_family!r} rig this limits model covers, got a "
            f"{rig_family(skeleton)!r} skeleton ({shown})"
        )
