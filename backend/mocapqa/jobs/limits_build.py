"""``mocapqa limits build`` on the Dask engine: the per-take half as tasks, training here.

Both builds start with one round of tasks, :func:`take_summary` per BVH file (its split group,
whether it has roles, its rig key, frame count and skeleton), from which the client picks the
build takes by the fixed split (:mod:`mocapqa.limits.split`); :func:`build_on_engine` runs
either build.

A per-rig build (:func:`mocapqa.limits.build.build_model`) then needs one more round:
:func:`take_role_rotations` per build take of the rig (its role joints' local rotations); the
maps and networks are built in the client (:func:`mocapqa.limits.build.rig_model_from_rotations`).

A canonical build (:func:`mocapqa.limits.build.build_canonical_model`) has a part that grows
with the corpus — reading every take, its world poses, its canonical rotations — and a part
that does not — one map and one network per role. The first runs here as Dask tasks that read
their own files (paths on storage the workers share), in three rounds, each returning small
results:

1. :func:`take_summary` per BVH file, from which the client picks the build takes (every
   take with roles; :func:`mocapqa.limits.split.held_back_names`);
2. :func:`world_sample` per build take: its world poses at the frames the frame estimate of
   its rig keeps (:func:`mocapqa.limits.canonical.pose_sample` over the rig's pooled frames,
   at most 4,000 per rig), from which the client frames every rig as
   :func:`mocapqa.limits.canonical.rig_frames` does;
3. :func:`take_rotations` per build take: its canonical rotations in its rig's frames.

The maps and networks are then built in the client
(:func:`mocapqa.limits.build.canonical_model_from_rotations`) from the same arrays in the same
order as in one process, so the model is the same (both builds tested on a local cluster).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Skeleton
from mocapqa.core.rig import SIDES, mapped_roles, require_mapped
from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.jobs.engine import Engine
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.limits.build import (
    BuildParams,
    canonical_model_from_rotations,
    rig_model_from_rotations,
    rig_roles,
    role_rotations,
    stored_frames,
)
from mocapqa.limits.canonical import (
    CanonicalFrames,
    canonical_frames,
    pose_sample,
    rig_key,
    without_stand_ins,
)
from mocapqa.limits.charting import canonical_rotations
from mocapqa.limits.model import LimitsModel, StoredFrames
from mocapqa.limits.rig import MODELLED_ROLES, rig_fingerprint
from mocapqa.limits.split import (
    check_rig_family,
    corpus_files,
    held_back_names,
    rig_positions,
    split_group,
)

__all__ = [
    "TakeSummary",
    "build_on_engine",
    "run_calls",
    "take_role_rotations",
    "take_rotations",
    "take_summary",
    "world_sample",
]

Step = Callable[[str], None]
CHUNK = 16
"""Most per-take calls sent to a worker in one task."""


@dataclass(frozen=True, slots=True)
class TakeSummary:
    """What the client needs of one BVH file to split the corpus and frame its rigs.

    Parameters
    ----------
    path : str
    group : tuple or None
        :func:`mocapqa.limits.split.split_group`.
    has_roles : bool
        Whether the skeleton has limb roles (a rig fingerprint).
    rig : str
        :func:`mocapqa.limits.canonical.rig_key`.
    n_frames : int
    skeleton : Skeleton
    """

    path: str
    group: tuple[object, ...] | None
    has_roles: bool
    rig: str
    n_frames: int
    skeleton: Skeleton

    @property
    def name(self) -> str:
        """The take's file name (what a model stores and ``--exclude`` names)."""
        return Path(self.path).name


def take_summary(path: str, mapping: dict[str, str] | None = None) -> TakeSummary:
    """Task: read one BVH file and summarise it (round 1); ``mapping`` gives roles where the
    skeleton has its joints."""
    motion = read_bvh(path)
    return TakeSummary(
        path=path,
        group=split_group(motion.skeleton),
        has_roles=bool(rig_fingerprint(motion.skeleton, mapping)),
        rig=rig_key(motion),
        n_frames=motion.n_frames,
        skeleton=motion.skeleton,
    )


def world_sample(path: str, frames: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """Task: world rotations ``(K, J, 4)`` and positions ``(K, J, 3)`` of the take at
    ``frames`` (indices, shape (K,)) (round 2)."""
    quats, positions = forward_kinematics(read_bvh(path))
    return quats[frames], positions[frames]


def take_rotations(path: str, frames: CanonicalFrames) -> FloatArray:
    """Task: canonical rotations ``(F, R, 4)`` of the take in its rig's ``frames`` (round 3)."""
    return canonical_rotations(read_bvh(path), frames)


def take_role_rotations(path: str, fingerprint: dict[str, tuple[str, str]]) -> FloatArray:
    """Task: local rotations ``(F, R, 4)`` of the take's joints of ``fingerprint`` (per-rig
    build, round 2)."""
    return role_rotations(read_bvh(path), fingerprint)


def run_calls(calls: Sequence[tuple[Callable[..., Any], tuple[Any, ...]]]) -> list[Any]:
    """Task: several per-take calls in one task (each Dask task costs the client tens of
    milliseconds; a take's work is about as short)."""
    return [f(*args) for f, args in calls]


def _gather(
    engine: Engine, calls: Sequence[tuple[Callable[..., Any], tuple[Any, ...]]], step: Step,
    label: str,
) -> list[Any]:  # fmt: skip
    """Run ``calls`` on the engine, in chunks of consecutive calls (about four per worker, at
    most :data:`CHUNK` calls each); their results in the order of ``calls``. ``step`` is
    called with ``label`` once per call as each chunk finishes."""
    from distributed import as_completed

    client = engine.client()
    size = max(1, min(CHUNK, -(-len(calls) // (4 * max(1, engine.n_workers())))))
    chunks = [list(calls[i : i + size]) for i in range(0, len(calls), size)]
    futures = [client.submit(run_calls, chunk, pure=False) for chunk in chunks]
    index = {future.key: i for i, future in enumerate(futures)}
    results: list[list[Any]] = [[] for _ in futures]
    for future in as_completed(futures):  # type: ignore[no-untyped-call]
        try:
            results[index[future.key]] = future.result()
        except InputError:
            raise
        except Exception as e:
            lost = engine.lost_after_settling(e)
            if lost is not None:
                raise lost from e
            raise
        future.release()
        for _ in results[index[future.key]]:
            step(label)
    return [result for chunk in results for result in chunk]


def _rig_frames(
    engine: Engine, takes: Sequence[TakeSummary], step: Step, mapping: dict[str, str] | None
) -> tuple[dict[str, CanonicalFrames], dict[str, StoredFrames]]:
    """Frames of every rig among ``takes`` (round 2), each estimated over all its takes as
    :func:`mocapqa.limits.canonical.rig_frames` does, keyed by rig key."""
    members: dict[str, list[TakeSummary]] = {}
    for take in takes:
        members.setdefault(take.rig, []).append(take)
    calls = []
    for group in members.values():
        counts = np.array([t.n_frames for t in group])
        starts = np.concatenate(([0], np.cumsum(counts)))
        keep = pose_sample(int(starts[-1]))
        for t, take in enumerate(group):
            local = np.arange(take.n_frames) if keep is None else keep - starts[t]
            if keep is not None:
                local = local[(local >= 0) & (local < take.n_frames)]
            calls.append((world_sample, (take.path, local)))
    samples = iter(_gather(engine, calls, step, "framing rigs"))
    known: dict[str, CanonicalFrames] = {}
    stored: dict[str, StoredFrames] = {}
    for key, group in members.items():
        worlds = [next(samples) for _ in group]
        pooled = (np.concatenate([w[0] for w in worlds]), np.concatenate([w[1] for w in worlds]))
        try:
            rig = mapped_roles(group[0].skeleton, mapping)
            frames = canonical_frames(group[0].skeleton, rig=rig, world=pooled)
        except InputError as e:
            raise InputError(f"{group[0].name}: {e}") from e
        known[key] = without_stand_ins(frames)  # a build leaves stood-in roles out
        stored[key] = stored_frames(group[0].skeleton, frames)
    return known, stored


def build_on_engine(
    engine: Engine,
    corpus_dir: Path,
    settings: BuildParams,
    rig: str | None = None,
    all_takes: bool = False,
    exclude: frozenset[str] | set[str] = frozenset(),
    on_total: Callable[[int], None] | None = None,
    step: Step | None = None,
    mapping: dict[str, str] | None = None,
) -> LimitsModel:
    """The model of ``mocapqa limits build``, with the per-take work on ``engine``: without
    ``rig`` the canonical model of :func:`mocapqa.limits.build.build_canonical_model` over
    :func:`mocapqa.jobs.limits_takes.canonical_takes`; with it, the per-rig model of
    :func:`mocapqa.limits.build.build_model` over :func:`mocapqa.jobs.limits_takes.rig_takes`.

    Parameters
    ----------
    engine : Engine
    corpus_dir : Path
        Folder of BVH takes (its ``bvh`` subfolder when it has one), read by the workers.
    settings : BuildParams
    rig : str, optional
        A family of :data:`mocapqa.limits.rig.RIG_FAMILIES`.
    all_takes : bool
        Every take, not only the build split.
    exclude : set of str
        Take file names to leave out.
    on_total : callable, optional
        Called with the number of steps to come once it is known (after round 1), and first
        with the files' count.
    step : callable, optional
        Called with a description after each step (a task done, a role or joint built).
    mapping : dict, optional
        Role key → joint name for a canonical build: the roles of the takes whose skeleton
        has its joints (:func:`mocapqa.core.rig.mapped_roles`).

    Raises
    ------
    InputError
        When ``rig`` is not a rig family (before any task); when no take has roles, or, with
        ``rig``, the folder has no rig of that family with two or more takes or no take of it
        is left; or a file cannot be read (naming it).
    ClusterError
        When the Dask scheduler cannot be reached or is lost.
    """
    if rig is not None:
        check_rig_family(rig)
    tick: Step = step or (lambda _: None)
    paths = [str(p) for p in corpus_files(corpus_dir)]
    if on_total is not None:
        on_total(len(paths))
    summaries: list[TakeSummary] = _gather(
        engine, [(take_summary, (p, mapping)) for p in paths], tick, "reading takes"
    )

    require_mapped(mapping, [s.skeleton for s in summaries])

    def total(n_more: int) -> None:
        if on_total is not None:
            on_total(len(paths) + n_more)

    if rig is None:
        takes = _canonical_takes(corpus_dir, summaries, all_takes, exclude)
        return _canonical_model(engine, takes, settings, total, tick, mapping)
    groups = [(s.name, s.group) for s in summaries]
    takes = [summaries[i] for i in rig_positions(groups, rig, corpus_dir, all_takes, exclude)]
    return _rig_model(engine, takes, settings, total, tick)


def _canonical_takes(
    corpus_dir: Path, summaries: Sequence[TakeSummary], all_takes: bool,
    exclude: frozenset[str] | set[str],
) -> list[TakeSummary]:  # fmt: skip
    """The takes of :func:`mocapqa.jobs.limits_takes.canonical_takes` among ``summaries``."""
    held = set() if all_takes else held_back_names([(s.name, s.group) for s in summaries])
    takes = [s for s in summaries if s.has_roles and s.name not in held and s.name not in exclude]
    if not takes:
        raise InputError(f"Expected BVH takes with limb roles in {corpus_dir}, got none")
    return takes


def _canonical_model(
    engine: Engine, takes: Sequence[TakeSummary], settings: BuildParams,
    total: Callable[[int], None], tick: Step, mapping: dict[str, str] | None,
) -> LimitsModel:  # fmt: skip
    """Rounds 2 and 3 of a canonical build of ``takes`` and its training; ``total`` is called
    with the steps to come after round 1."""
    total(2 * len(takes) + len(SIDES) * len(MODELLED_ROLES))
    known, stored = _rig_frames(engine, takes, tick, mapping)
    calls = [(take_rotations, (t.path, known[t.rig])) for t in takes]
    rotations = _gather(engine, calls, tick, "charting takes")
    return canonical_model_from_rotations(
        [t.name for t in takes],
        [(known[t.rig].roles, q) for t, q in zip(takes, rotations, strict=True)],
        stored,
        sum(t.n_frames for t in takes),
        settings,
        lambda role: tick(f"built {role}"),
    )


def _rig_model(
    engine: Engine, takes: Sequence[TakeSummary], settings: BuildParams,
    total: Callable[[int], None], tick: Step,
) -> LimitsModel:  # fmt: skip
    """Round 2 of a per-rig build of ``takes`` (the chosen takes of one rig) and its
    training; ``total`` is called with the steps to come after round 1."""
    fingerprint = rig_roles([t.skeleton for t in takes], [t.name for t in takes])
    total(len(takes) + len(fingerprint))
    calls = [(take_role_rotations, (t.path, fingerprint)) for t in takes]
    rotations = _gather(engine, calls, tick, "charting takes")
    return rig_model_from_rotations(
        takes[0].skeleton,
        [t.name for t in takes],
        rotations,
        settings,
        lambda name: tick(f"built {name}"),
    )
