"""``mocapqa bench limits``: discriminator accuracy, false flags, injected-error recall, speed.

Corpus split (fixed rule): every BVH take under ``CORPUS/bvh`` is grouped by rig fingerprint
(:func:`mocapqa.limits.rig.rig_fingerprint`); groups of fewer than two takes are left out. In
each group the takes are sorted by file name and every take at a position ``i`` with
``i % 4 == 1`` is held back (never used to build); the rest build the model. This holds back
10 of 41 Bandai takes, 4 of 15 Character Creator takes and 1 of the 2 CMU-style takes.

Figures per rig: the discriminator's accuracy, precision and recall per joint on its held-out
synthetic test split; the false-flag rate (share of frame × joints outside the limits) on the
clean held-back takes; the share of injected twist-error frames (offsets ≥ 60°,
:func:`mocapqa.twist.inject.inject_twist_errors`) on which the target joint or its compensating
child is flagged; and check speed in joint-frames per second for the map and the network.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.jobs.limits_takes import canonical_takes, corpus_takes, rig_takes, split_takes
from mocapqa.limits.analysis import check_limits, limit_params
from mocapqa.limits.build import DEFAULT_BUILD, BuildParams, build_model
from mocapqa.limits.model import LimitsModel
from mocapqa.limits.occupancy import is_valid
from mocapqa.limits.rig import rig_fingerprint
from mocapqa.limits.split import (
    check_rig_family,
    corpus_files,
    held_back,
    held_back_names,
    rig_positions,
    split_group,
    split_positions,
)
from mocapqa.twist.inject import inject_twist_errors

__all__ = [
    "JointFigures",
    "RigFigures",
    "RigTakes",
    "bench_rig",
    "canonical_takes",
    "check_rig_family",
    "corpus_files",
    "corpus_rigs",
    "held_back",
    "held_back_names",
    "rig_positions",
    "rig_takes",
    "role_takes",
    "split_group",
    "split_positions",
    "tiled_take",
]


@dataclass(frozen=True, slots=True)
class RigTakes:
    """The takes of one rig family, split by the fixed rule.

    Parameters
    ----------
    family : str
    build, held_back : tuple of (str, Motion)
        Take file names and motions.
    """

    family: str
    build: tuple[tuple[str, Motion], ...]
    held_back: tuple[tuple[str, Motion], ...]


@dataclass(frozen=True, slots=True)
class JointFigures:
    """Figures of one joint: synthetic test scores and held-back false flags."""

    name: str
    accuracy: float
    precision: float
    recall: float
    hidden_size: int
    false_flag_rate: float


@dataclass(frozen=True, slots=True)
class RigFigures:
    """Figures of one rig.

    Parameters
    ----------
    family : str
    n_build_takes, n_held_back_takes, n_build_frames, n_held_back_frames : int
    joints : tuple of JointFigures
    false_flag_rate : float
        Map, over every held-back frame × joint.
    network_false_flag_rate : float
        The same with the discriminator deciding.
    injected_flag_rate : float
        Share of injected (frame, target) errors flagged on the target or its child.
    n_injected : int
    lookup_joint_frames_per_s : float
        Charting plus the map lookup (validity only).
    map_joint_frames_per_s, network_joint_frames_per_s : float
        Full checks (validity and scores) with the map or the network deciding.
    """

    family: str
    n_build_takes: int
    n_held_back_takes: int
    n_build_frames: int
    n_held_back_frames: int
    joints: tuple[JointFigures, ...]
    false_flag_rate: float
    network_false_flag_rate: float
    injected_flag_rate: float
    n_injected: int
    lookup_joint_frames_per_s: float
    map_joint_frames_per_s: float
    network_joint_frames_per_s: float


def corpus_rigs(corpus_dir: Path, families: tuple[str, ...] | None = None) -> list[RigTakes]:
    """Group the corpus' BVH takes by rig fingerprint and split them.

    Parameters
    ----------
    corpus_dir : Path
        Folder with a ``bvh`` subfolder (or BVH files) searched recursively.
    families : tuple of str, optional
        Keep only these family labels.

    Returns
    -------
    list of RigTakes
        Groups of two or more takes, sorted by family label.
    """
    read = split_takes(corpus_dir, families)
    rigs = [
        RigTakes(
            str(key[0]),
            tuple((read[i][0], read[i][2]) for i in build),
            tuple((read[i][0], read[i][2]) for i in back),
        )
        for key, (build, back) in split_positions([key for _, key, _ in read]).items()
    ]
    return sorted(rigs, key=lambda r: r.family)


def role_takes(corpus_dir: Path) -> list[tuple[str, Motion]]:
    """Every BVH take under ``corpus_dir`` whose skeleton has limb roles, sorted by file name.

    Raises
    ------
    InputError
        As :func:`mocapqa.jobs.limits_takes.corpus_takes`.
    """
    return [(name, m) for name, m in corpus_takes(corpus_dir) if rig_fingerprint(m.skeleton)]


def tiled_take(motion: Motion, min_frames: int = 50_000) -> Motion:
    """``motion`` repeated end to end to at least ``min_frames`` frames (a take long enough
    for a check's fixed costs not to dominate its speed)."""
    tiles = max(1, -(-min_frames // motion.n_frames))
    return Motion(
        motion.skeleton,
        np.tile(motion.quats, (tiles, 1, 1)),
        np.tile(motion.translations, (tiles, 1, 1)),
        motion.fps,
    )


def _speed(model: LimitsModel, motion: Motion, method: str, repeats: int) -> float:
    """Joint-frames per second of a full check ("map", "network") or of the lookup alone."""
    # A long take (the held-back take tiled to ≥ 50,000 frames) so fixed costs do not dominate.
    motion = tiled_take(motion)

    def run() -> None:
        if method == "lookup":
            params = limit_params(motion, model)
            for j, joint in enumerate(model.joints):
                is_valid(joint.occupancy, params[:, j])
        else:
            check_limits(motion, model, method=method)

    run()
    start = time.perf_counter()
    for _ in range(repeats):
        run()
    elapsed = time.perf_counter() - start
    return repeats * motion.n_frames * len(model.joints) / max(elapsed, 1e-9)


def _injected_hits(
    model: LimitsModel, motion: Motion, rng: np.random.Generator, min_offset_deg: float
) -> tuple[int, int]:
    """Twist errors injected into ``motion`` (offsets from ``min_offset_deg`` to 180°): the
    error frames flagged on the target joint or its child, and the error frames."""
    corrupted, truth = inject_twist_errors(
        motion, rng, min_offset_deg=min_offset_deg, max_offset_deg=180.0
    )
    bad = check_limits(corrupted, model)
    column = {name: k for k, name in enumerate(bad.joint_names)}
    names = motion.skeleton.names
    hits, injected = 0, 0
    for target, child in zip(truth.targets, truth.children, strict=True):
        error_frames = np.flatnonzero(truth.error_mask[:, target])
        flagged = np.zeros(error_frames.size, dtype=bool)
        for joint in (target, child):
            if names[joint] in column:
                flagged |= ~bad.valid[error_frames, column[names[joint]]]
        hits += int(flagged.sum())
        injected += int(error_frames.size)
    return hits, injected


def _joint_figures(model: LimitsModel, flags: FloatArray, frames: int) -> tuple[JointFigures, ...]:
    """Each joint's discriminator scores and its share of flagged held-back frames
    (``flags``: flagged frames per joint, shape (n_joints,); ``frames``: held-back frames)."""
    return tuple(
        JointFigures(
            name=j.name,
            accuracy=j.scores.accuracy if j.scores else float("nan"),
            precision=j.scores.precision if j.scores else float("nan"),
            recall=j.scores.recall if j.scores else float("nan"),
            hidden_size=j.scores.hidden_size if j.scores else 0,
            false_flag_rate=float(flags[k] / max(frames, 1)),
        )
        for k, j in enumerate(model.joints)
    )


def bench_rig(
    rig: RigTakes,
    settings: BuildParams = DEFAULT_BUILD,
    seed: int = 0,
    min_offset_deg: float = 60.0,
    progress: Callable[[str], None] | None = None,
    model: LimitsModel | None = None,
) -> tuple[LimitsModel, RigFigures]:
    """Build a model on a rig's build takes and measure it on the held-back takes.

    Parameters
    ----------
    rig : RigTakes
    settings : BuildParams
    seed : int
        Seed of the injected errors.
    min_offset_deg : float
        Smallest injected offset magnitude, degrees (up to 180°).
    progress : callable, optional
        Called with each built joint's name.
    model : LimitsModel, optional
        A model already built on exactly this rig's build takes (a shipped one); skips building.

    Returns
    -------
    model : LimitsModel
    figures : RigFigures
    """
    names = tuple(n for n, _ in rig.build)
    if model is None:
        model = build_model([m for _, m in rig.build], names, settings, progress=progress)
    elif model.takes != names:
        raise InputError(
            f"Expected a model built on the {len(names)} build takes of {rig.family!r}, got one "
            f"built on {len(model.takes)} other takes"
        )
    rng = np.random.default_rng(seed)
    flags = np.zeros(len(model.joints))
    network_flags = 0.0
    frames = 0
    hits, injected = 0, 0
    for _, motion in rig.held_back:
        report = check_limits(motion, model)
        flags += (~report.valid).sum(axis=0)
        if all(j.network is not None for j in model.joints):
            network_flags += float((~check_limits(motion, model, "network").valid).sum())
        frames += motion.n_frames
        take_hits, take_injected = _injected_hits(model, motion, rng, min_offset_deg)
        hits += take_hits
        injected += take_injected
    longest = max((m for _, m in rig.held_back), key=lambda m: m.n_frames)
    joints = _joint_figures(model, flags, frames)
    has_network = all(j.network is not None for j in model.joints)
    figures = RigFigures(
        family=rig.family,
        n_build_takes=len(rig.build),
        n_held_back_takes=len(rig.held_back),
        n_build_frames=model.n_frames,
        n_held_back_frames=frames,
        joints=joints,
        false_flag_rate=float(flags.sum() / max(frames * len(model.joints), 1)),
        network_false_flag_rate=network_flags / max(frames * len(model.joints), 1)
        if has_network
        else float("nan"),
        injected_flag_rate=hits / max(injected, 1),
        n_injected=injected,
        lookup_joint_frames_per_s=_speed(model, longest, "lookup", 5),
        map_joint_frames_per_s=_speed(model, longest, "map", 5),
        network_joint_frames_per_s=_speed(model, longest, "network", 2)
        if has_network
        else float("nan"),
    )
    return model, figures
