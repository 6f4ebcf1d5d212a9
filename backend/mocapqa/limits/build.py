"""Build a limits model from takes of one rig family.

Steps per modelled joint (roles from :data:`mocapqa.limits.rig.MODELLED_ROLES`): gather its local
rotations over every frame of every take; choose the reference rotation (the chordal mean,
the dominant eigenvector of ``Σ q qᵀ``, or the identity for the paper's setting); chart the
rotations as ``(s1, s2, τ)`` relative to it; build the lookup map; optionally train the
discriminator on the map's synthetic labels.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Motion, Skeleton
from mocapqa.core.rig import SIDES, role_key
from mocapqa.errors import InputError
from mocapqa.limits.canonical import CANONICAL_AXIS, CanonicalFrames, rig_frames, rig_key
from mocapqa.limits.charting import canonical_quats
from mocapqa.limits.discriminator import DiscriminatorParams, train_discriminator
from mocapqa.limits.expmap import limit_params_from_quats
from mocapqa.limits.model import JointLimits, LimitsModel, StoredFrames
from mocapqa.limits.occupancy import OccupancyParams, build_occupancy
from mocapqa.limits.rig import (
    MODELLED_ROLES,
    bone_axis,
    fingerprint_mismatches,
    rig_family,
    rig_fingerprint,
)

__all__ = [
    "DEFAULT_BUILD",
    "PAPER_BUILD",
    "BuildParams",
    "build_canonical_model",
    "build_model",
    "canonical_model_from_rotations",
    "mean_rotation",
    "rig_model_from_rotations",
    "rig_roles",
    "role_rotations",
    "stored_frames",
    "with_rig_frames",
]


@dataclass(frozen=True, slots=True)
class BuildParams:
    """How a model is built.

    Parameters
    ----------
    occupancy : OccupancyParams
    discriminator : DiscriminatorParams or None
        None skips the networks (map only).
    reference : {"mean", "identity"}
        Reference rotation per joint; "identity" is the paper's setting.
    seed : int
        Seed of the synthetic sets and networks.
    """

    occupancy: OccupancyParams = field(default_factory=OccupancyParams)
    discriminator: DiscriminatorParams | None = field(default_factory=DiscriminatorParams)
    reference: str = "mean"
    seed: int = 0

    def __post_init__(self) -> None:
        if self.reference not in ("mean", "identity"):
            raise InputError(f"Expected `reference` 'mean' or 'identity', got {self.reference!r}")


# The shipped models' setting, chosen on the build split (docs/limits.md).
DEFAULT_BUILD = BuildParams(
    occupancy=OccupancyParams(bin_deg=15.0, dilation_bins=2, tau_margin_deg=40.0, interpolate=True)
)
# The paper's setting: 1° bins, no dilation, no margin, identity reference.
PAPER_BUILD = BuildParams(occupancy=OccupancyParams(bin_deg=1.0), reference="identity")


def mean_rotation(quats: FloatArray) -> FloatArray:
    """Chordal L2 mean of unit quaternions ``(N, 4)``: the top eigenvector of ``Σ q qᵀ``, (4,)."""
    _, vectors = np.linalg.eigh(quats.T @ quats)
    mean = vectors[:, -1]
    return np.asarray(mean if mean[3] >= 0 else -mean, dtype=np.float64)


def build_model(
    motions: Sequence[Motion],
    take_names: Sequence[str],
    settings: BuildParams = DEFAULT_BUILD,
    progress: Callable[[str], None] | None = None,
) -> LimitsModel:
    """Build a limits model from takes of one rig.

    Parameters
    ----------
    motions : sequence of Motion
        Takes of one rig family (same fingerprint).
    take_names : sequence of str
        One name per take, stored in the model.
    settings : BuildParams
    progress : callable, optional
        Called with a joint name after each joint is built.

    Returns
    -------
    LimitsModel

    Raises
    ------
    InputError
        If there are no takes, the names do not match the takes, a take is of another rig, or
        the rig has none of the modelled roles.
    """
    fingerprint = rig_roles([m.skeleton for m in motions], take_names)
    return rig_model_from_rotations(
        motions[0].skeleton,
        take_names,
        [role_rotations(m, fingerprint) for m in motions],
        settings,
        progress,
    )


def rig_roles(
    skeletons: Sequence[Skeleton], take_names: Sequence[str]
) -> dict[str, tuple[str, str]]:
    """The fingerprint (:func:`mocapqa.limits.rig.rig_fingerprint`) shared by takes of one rig.

    Raises
    ------
    InputError
        If there are no takes, the names do not match the takes, the first rig has none of the
        modelled roles, or a take is of another rig.
    """
    _check_names(len(skeletons), take_names)
    fingerprint = rig_fingerprint(skeletons[0])
    if not fingerprint:
        raise InputError(f"Expected a skeleton with limb roles, got none in {take_names[0]!r}")
    for skeleton, name in zip(skeletons, take_names, strict=True):
        problems = fingerprint_mismatches(fingerprint, skeleton)
        if problems:
            raise InputError(f"Expected every take of one rig, got {name!r}: {problems[0]}")
    return fingerprint


def role_rotations(motion: Motion, fingerprint: dict[str, tuple[str, str]]) -> FloatArray:
    """The per-take half of :func:`build_model`: local rotations ``(F, R, 4)`` of the
    fingerprint's joints, in its order."""
    return motion.quats[:, [motion.skeleton.index(name) for name, _ in fingerprint.values()]]


def rig_model_from_rotations(
    skeleton: Skeleton,
    take_names: Sequence[str],
    rotations: Sequence[FloatArray],
    settings: BuildParams = DEFAULT_BUILD,
    progress: Callable[[str], None] | None = None,
) -> LimitsModel:
    """The corpus-wide half of :func:`build_model`: a map (and network) per joint from every
    take's :func:`role_rotations` (the per-take half may run elsewhere, e.g. on Dask).

    Parameters
    ----------
    skeleton : Skeleton
        Of the rig (of the first take); :func:`rig_roles` of every take has checked it.
    take_names : sequence of str
    rotations : sequence of ndarray
        Per take, in the order of ``take_names``: ``(F, R, 4)``.
    settings, progress
        As for :func:`build_model`.
    """
    fingerprint = rig_fingerprint(skeleton)
    roles = list(fingerprint)
    quats = np.concatenate(rotations, axis=0)
    rng = np.random.default_rng(settings.seed)
    joints = []
    for j, role in enumerate(roles):
        name = fingerprint[role][0]
        axis = bone_axis(skeleton, skeleton.index(name))
        joints.append(_joint_limits(role, name, quats[:, j], axis, settings, rng))
        if progress is not None:
            progress(name)
    return LimitsModel(
        rig_family=rig_family(skeleton),
        fingerprint=fingerprint,
        joints=tuple(joints),
        occupancy_params=settings.occupancy,
        reference=settings.reference,
        corpus_hash=_corpus_hash(take_names, rotations),
        takes=tuple(take_names),
        n_frames=int(quats.shape[0]),
    )


def build_canonical_model(
    motions: Sequence[Motion],
    take_names: Sequence[str],
    settings: BuildParams = DEFAULT_BUILD,
    progress: Callable[[str], None] | None = None,
    mapping: Mapping[str, str] | None = None,
) -> LimitsModel:
    """Build one rig-independent model per role from takes of any rigs with roles.

    Takes are grouped by rig (:func:`mocapqa.limits.canonical.rig_key`); each rig's canonical
    frames are estimated over all its takes and stored in the model; every take's role joints
    are charted in them, and a role's map pools every take that has the role.

    Parameters
    ----------
    motions : sequence of Motion
        Takes of any rigs whose roles are found.
    take_names : sequence of str
    settings : BuildParams
    progress : callable, optional
        Called with a role key after each role is built.
    mapping : mapping, optional
        Role key → joint name for the rigs whose joints it names (the others keep the roles
        found by name); stored with those rigs' frames, so their takes are checked with it.

    Returns
    -------
    LimitsModel
        ``frame == "canonical"``; joint names are the role keys.

    Raises
    ------
    InputError
        If there are no takes, the names do not match, or a take has no limb roles.
    """
    _check_names(len(motions), take_names)
    known, stored = _frames_by_rig(motions, take_names, mapping)
    rotations = [canonical_quats(m, known=known[rig_key(m)]) for m in motions]
    return canonical_model_from_rotations(
        take_names,
        [(frames.roles, quats) for frames, quats in rotations],
        stored,
        int(sum(m.n_frames for m in motions)),
        settings,
        progress,
    )


def canonical_model_from_rotations(
    take_names: Sequence[str],
    rotations: Sequence[tuple[tuple[str, ...], FloatArray]],
    stored: dict[str, StoredFrames],
    n_frames: int,
    settings: BuildParams = DEFAULT_BUILD,
    progress: Callable[[str], None] | None = None,
) -> LimitsModel:
    """The corpus-wide half of :func:`build_canonical_model`: maps and networks per role from
    every take's canonical rotations (the per-take half may run elsewhere, e.g. on Dask).

    Parameters
    ----------
    take_names : sequence of str
    rotations : sequence of (tuple of str, ndarray)
        Per take, in the order of ``take_names``: its role keys and canonical rotations
        ``(F, R, 4)`` in its rig's frames (:func:`mocapqa.limits.charting.canonical_quats`).
    stored : dict
        :func:`mocapqa.limits.canonical.rig_key` → the frames of every rig among the takes.
    n_frames : int
        Frames of all the takes.
    settings : BuildParams
    progress : callable, optional
        Called with a role key after each role is built.

    Returns
    -------
    LimitsModel
    """
    samples: dict[str, list[FloatArray]] = {}
    for roles_of_take, quats in rotations:
        for k, role in enumerate(roles_of_take):
            samples.setdefault(role, []).append(quats[:, k])
    order = [role_key(s, r) for s in SIDES for r in MODELLED_ROLES]
    rng = np.random.default_rng(settings.seed)
    joints = []
    for role in (r for r in order if r in samples):
        quats = np.concatenate(samples[role], axis=0)
        joints.append(_joint_limits(role, role, quats, CANONICAL_AXIS, settings, rng))
        if progress is not None:
            progress(role)
    return LimitsModel(
        rig_family="canonical",
        fingerprint={},
        joints=tuple(joints),
        occupancy_params=settings.occupancy,
        reference=settings.reference,
        corpus_hash=_corpus_hash(take_names, [quats for _, quats in rotations]),
        takes=tuple(take_names),
        n_frames=n_frames,
        frame="canonical",
        rig_frames=stored,
    )


def _check_names(n_takes: int, take_names: Sequence[str]) -> None:
    """One name per take and at least one take, or an InputError."""
    if not n_takes or n_takes != len(take_names):
        raise InputError(
            f"Expected one name per take and at least one take, got {n_takes} takes and "
            f"{len(take_names)} names"
        )


def _joint_limits(
    role: str, name: str, quats: FloatArray, axis: FloatArray, settings: BuildParams,
    rng: np.random.Generator,
) -> JointLimits:  # fmt: skip
    """One joint's map (and network) from its rotations ``quats`` (N, 4) about its bone
    ``axis`` (3,); ``rng`` draws the network's synthetic set (shared by the joints in turn)."""
    if settings.reference == "mean":
        reference = mean_rotation(quats)
    else:
        reference = np.array([0.0, 0.0, 0.0, 1.0])
    params = limit_params_from_quats(quats[:, None], axis[None], reference[None])
    occupancy = build_occupancy(params[:, 0], settings.occupancy)
    network, scores = None, None
    if settings.discriminator is not None:
        network, scores = train_discriminator(occupancy, settings.discriminator, rng)
    return JointLimits(
        role=role,
        name=name,
        axis=np.array(axis, dtype=np.float64),
        reference=reference,
        occupancy=occupancy,
        network=network,
        scores=scores,
        n_samples=int(quats.shape[0]),
    )


def _corpus_hash(take_names: Sequence[str], rotations: Sequence[FloatArray]) -> str:
    """SHA-256 of every take's name and rotations, in order (what a model was built from)."""
    digest = hashlib.sha256()
    for name, quats in zip(take_names, rotations, strict=True):
        digest.update(name.encode("utf-8"))
        digest.update(np.ascontiguousarray(quats).tobytes())
    return digest.hexdigest()


def stored_frames(skeleton: Skeleton, frames: CanonicalFrames) -> StoredFrames:
    """``frames`` of the rig of ``skeleton`` as a model stores them (joints by name)."""
    names = skeleton.names
    return StoredFrames(
        family=rig_family(skeleton),
        roles=frames.roles,
        joints=tuple(names[j] for j in frames.joints),
        parents=tuple(names[j] for j in frames.parents),
        frames=frames.frames,
        parent_frames=frames.parent_frames,
    )


def _frames_by_rig(
    motions: Sequence[Motion], take_names: Sequence[str], mapping: Mapping[str, str] | None
) -> tuple[dict[str, CanonicalFrames], dict[str, StoredFrames]]:
    """Canonical frames of every rig among ``motions``, each estimated over all its takes,
    keyed by :func:`mocapqa.limits.canonical.rig_key`; and the same as stored in a model."""
    groups: dict[str, list[int]] = {}
    for i, motion in enumerate(motions):
        groups.setdefault(rig_key(motion), []).append(i)
    known: dict[str, CanonicalFrames] = {}
    stored: dict[str, StoredFrames] = {}
    for key, members in groups.items():
        try:
            frames = rig_frames([motions[i] for i in members], mapping)
        except InputError as e:
            raise InputError(f"{take_names[members[0]]}: {e}") from e
        known[key] = frames
        stored[key] = stored_frames(motions[members[0]].skeleton, frames)
    return known, stored


def with_rig_frames(
    model: LimitsModel,
    motions: Sequence[Motion],
    take_names: Sequence[str],
    mapping: Mapping[str, str] | None = None,
) -> LimitsModel:
    """A canonical model that also knows the frames of the rigs of ``motions``.

    Each rig the model has not seen is framed once over all its takes given here (as a build
    does), instead of from each take checked: a short take whose frames are mostly damaged
    would otherwise be framed by its own errors. The takes are not added to the maps, so they
    need not be clean in every frame, only mostly; rigs the model knows keep their frames.

    Raises
    ------
    InputError
        If the model is not canonical, or a take has no limb roles.
    """
    if model.frame != "canonical":
        raise InputError(f"Expected a canonical limits model, got a {model.rig_family!r} one")
    _, stored = _frames_by_rig(motions, take_names, mapping)
    added = {k: v for k, v in stored.items() if k not in model.rig_frames}
    return replace(model, rig_frames={**model.rig_frames, **added})
