"""The twist benchmark: the paper's synthetic protocol on the real takes, for both methods.

For each take and repeat, errors are injected with
:func:`mocapqa.twist.inject.inject_twist_errors` (seed derived from ``seed``, the file name and
the repeat), then refined by each method; the target joints' rotation errors on the injected
frames feed the paper's Table 1 (MAE, RMSE before/after, FSR) and Table 2 (per side × segment:
MAE after, RER, FSR). Each clean take is also refined as is, for the clean-data figure (share of
frame × joint rotations changed by more than 1°, and the largest change), and timed for the
speed in frames per second (detection and refinement, parsing excluded).

Takes are grouped by rig: ``cmu`` (the cgspeed conversion), ``iclone`` (Character Creator
retargets) and ``bandai``. Within each rig, files at even positions of the sorted list form the
*fit* set (the one the robust defaults were tuned on) and those at odd positions the *held-out*
set; results are reported for both and overall.
"""

from __future__ import annotations

import time
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.metrics.twist import (
    CleanChange,
    TwistAccuracy,
    clean_change,
    rotation_errors_deg,
    twist_accuracy,
)
from mocapqa.twist.analysis import analyze_twist, detect_chains
from mocapqa.twist.angles import chain_geometry
from mocapqa.twist.detect import PaperParams, RobustParams
from mocapqa.twist.inject import inject_twist_errors
from mocapqa.twist.refine import refine_quats

__all__ = [
    "RIGS",
    "BenchFile",
    "MethodResult",
    "TwistBenchResult",
    "find_bench_files",
    "rig_of",
    "run_twist_bench",
    "speed_frames_per_s",
]

# Rig families reported separately, by corpus folder.
RIGS = ("cmu", "iclone", "bandai")


@dataclass(frozen=True, slots=True)
class BenchFile:
    """A take of the benchmark.

    Parameters
    ----------
    path : Path
    rig : str
        One of :data:`RIGS`.
    held_out : bool
        Whether the file belongs to the held-out set.
    """

    path: Path
    rig: str
    held_out: bool


@dataclass(slots=True)
class MethodResult:
    """Accumulated errors and clean-data changes of one method (mutable while running).

    Parameters
    ----------
    before, after : dict
        ``(rig, held_out, side, segment)`` → list of per-frame errors (degrees).
    clean : dict
        ``(rig, held_out)`` → list of :class:`CleanChange`.
    seconds, frames : dict
        ``rig`` → detection + refinement time (s) and frames processed on the clean takes.
    """

    before: dict[tuple[str, bool, str, str], list[np.ndarray]] = field(default_factory=dict)
    after: dict[tuple[str, bool, str, str], list[np.ndarray]] = field(default_factory=dict)
    clean: dict[tuple[str, bool], list[CleanChange]] = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)
    frames: dict[str, int] = field(default_factory=dict)

    def accuracy(
        self,
        rigs: Sequence[str] = RIGS,
        held_out: bool | None = None,
        side: str | None = None,
        segment: str | None = None,
    ) -> TwistAccuracy:
        """Paper metrics over the selected error frames (None selects all)."""
        keys = [
            k
            for k in self.before
            if k[0] in rigs
            and (held_out is None or k[1] == held_out)
            and (side is None or k[2] == side)
            and (segment is None or k[3] == segment)
        ]
        if not keys:
            return twist_accuracy(np.zeros(0), np.zeros(0))
        before = np.concatenate([a for k in keys for a in self.before[k]])
        after = np.concatenate([a for k in keys for a in self.after[k]])
        return twist_accuracy(before, after)

    def clean_figure(self, rigs: Sequence[str] = RIGS, held_out: bool | None = None) -> CleanChange:
        """Clean-data changes summed over the selected takes."""
        items = [
            c
            for (rig, hold), cs in self.clean.items()
            if rig in rigs and (held_out is None or hold == held_out)
            for c in cs
        ]
        return CleanChange(
            n_cells=sum(c.n_cells for c in items),
            n_changed=sum(c.n_changed for c in items),
            max_change_deg=max((c.max_change_deg for c in items), default=0.0),
        )

    def speed(self, rigs: Sequence[str] = RIGS) -> float:
        """Frames per second of detection + refinement over the clean takes of ``rigs``."""
        seconds = sum(self.seconds.get(r, 0.0) for r in rigs)
        frames = sum(self.frames.get(r, 0) for r in rigs)
        return frames / seconds if seconds > 0 else 0.0


@dataclass(frozen=True, slots=True)
class TwistBenchResult:
    """Results per method name.

    Parameters
    ----------
    methods : dict
        Label → :class:`MethodResult`.
    n_files : int
        Takes used.
    n_injections : int
        Injected takes per method.
    """

    methods: dict[str, MethodResult]
    n_files: int
    n_injections: int


def rig_of(path: Path) -> str | None:
    """The rig of a corpus file from its folder, or None for other rigs."""
    parts = path.parts
    if "iclone" in parts:
        return "iclone"
    if "bandai" in parts:
        return "bandai"
    if "cmu" in parts:
        return "cmu"
    return None


def find_bench_files(data_dir: Path, files_per_rig: int | None = None) -> list[BenchFile]:
    """The benchmark takes under ``data_dir`` (a corpus ``bvh`` folder or its parent).

    Parameters
    ----------
    data_dir : Path
    files_per_rig : int, optional
        Keep the first N files of each rig (sorted by name).

    Returns
    -------
    list of BenchFile

    Raises
    ------
    InputError
        If no take of a known rig is found.
    """
    by_rig: dict[str, list[Path]] = {r: [] for r in RIGS}
    for path in sorted(Path(data_dir).glob("**/*.bvh")):
        rig = rig_of(path)
        if rig is not None:
            by_rig[rig].append(path)
    out: list[BenchFile] = []
    for rig, paths in by_rig.items():
        chosen = paths if files_per_rig is None else paths[:files_per_rig]
        out += [BenchFile(p, rig, i % 2 == 1) for i, p in enumerate(chosen)]
    if not out:
        raise InputError(f"Expected BVH takes of rigs {RIGS} under {data_dir}, got none")
    return out


def speed_frames_per_s(
    motion: Motion, method: str, params: RobustParams | PaperParams | None = None
) -> tuple[float, float, float]:
    """Frames per second of detection + refinement on ``motion`` (best of three runs each).

    Returns
    -------
    core_wall : float
        :func:`mocapqa.twist.analysis.detect_chains` plus
        :func:`mocapqa.twist.refine.refine_quats` on the quaternion array, wall-clock time.
    core_cpu : float
        The same in process CPU time, which a machine shared with other jobs disturbs less.
    end_to_end : float
        :func:`mocapqa.twist.analysis.analyze_twist`, which also builds and validates the
        refined :class:`Motion` and its Euler hints, wall-clock time.
    """
    geometries = tuple(
        chain_geometry(motion.skeleton, c) for c in limb_chains(find_roles(motion.skeleton))
    )
    best_wall = best_cpu = best_full = np.inf
    for _ in range(3):
        wall, cpu = time.perf_counter(), time.process_time()
        detection = detect_chains(motion.quats, geometries, motion.fps, method, params)
        refine_quats(motion.quats, geometries, detection.offsets)
        best_wall = min(best_wall, time.perf_counter() - wall)
        best_cpu = min(best_cpu, time.process_time() - cpu)
        start = time.perf_counter()
        analyze_twist(motion, method, params=params)
        best_full = min(best_full, time.perf_counter() - start)
    n = motion.n_frames
    return n / best_wall, n / max(best_cpu, 1e-9), n / best_full


def run_twist_bench(
    files: Sequence[BenchFile],
    methods: dict[str, tuple[str, RobustParams | PaperParams | None]],
    seed: int = 0,
    repeats: int = 2,
    on_file: Callable[[BenchFile], None] | None = None,
) -> TwistBenchResult:
    """Inject, refine and score every take with every method.

    Parameters
    ----------
    files : sequence of BenchFile
    methods : dict
        Label → (method name, parameters or None).
    seed : int
        Base seed; each injection uses ``(seed, crc32(file name), repeat)``.
    repeats : int
        Injections per take.
    on_file : callable, optional
        Called after each take (progress).

    Returns
    -------
    TwistBenchResult
    """
    results = {label: MethodResult() for label in methods}
    n_injections = 0
    for bench_file in files:
        motion = read_bvh(bench_file.path)
        name_key = zlib.crc32(bench_file.path.name.encode())
        injected = []
        for repeat in range(repeats):
            rng = np.random.default_rng((seed, name_key, repeat))
            try:
                injected.append(inject_twist_errors(motion, rng))
            except InputError:
                continue
        n_injections += len(injected)
        has_rotation = np.array([bool(motion.skeleton.rotation_order(j)) for j in
                                 range(motion.skeleton.n_joints)])  # fmt: skip
        for label, (method, params) in methods.items():
            result = results[label]
            for corrupted, truth in injected:
                refined = analyze_twist(corrupted, method, params=params).refined
                for k, target in enumerate(truth.targets):
                    rows = truth.error_mask[:, target]
                    key = (bench_file.rig, bench_file.held_out, truth.sides[k], truth.segments[k])
                    clean_rows = truth.clean_quats[rows, target]
                    result.before.setdefault(key, []).append(
                        rotation_errors_deg(clean_rows, corrupted.quats[rows, target])
                    )
                    result.after.setdefault(key, []).append(
                        rotation_errors_deg(clean_rows, refined.quats[rows, target])
                    )
            start = time.perf_counter()
            analysis = analyze_twist(motion, method, params=params)
            elapsed = time.perf_counter() - start
            result.seconds[bench_file.rig] = result.seconds.get(bench_file.rig, 0.0) + elapsed
            result.frames[bench_file.rig] = result.frames.get(bench_file.rig, 0) + motion.n_frames
            mask = np.broadcast_to(has_rotation, motion.quats.shape[:2])
            change = clean_change(motion.quats, analysis.refined.quats, 1.0, mask)
            result.clean.setdefault((bench_file.rig, bench_file.held_out), []).append(change)
        if on_file is not None:
            on_file(bench_file)
    return TwistBenchResult(results, len(files), n_injections)
