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
*fit* set (the one the confidence calibration is fitted on) and those at odd positions the
*held-out* set; results are reported for both and overall. The takes of
:data:`REAL_ERROR_TAKES` carry real twist errors and are never injected into (they are
evaluation data only, see :mod:`mocapqa_bench.natural`).

Every interval a method reports, on injected and on clean takes, is recorded with its
confidence features and whether it is *right*: applying it alone removes at least 80 % of the
injected twist error on its frames and raises no frame's error by more than 1° (an interval on
a clean take is never right). Those records feed the calibration fit and reliability table.
"""

from __future__ import annotations

import functools
import time
import zlib
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import FloatArray
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
from mocapqa.twist.analysis import TwistAnalysis, analyze_twist, detect_chains
from mocapqa.twist.angles import chain_geometry, wrap_angle
from mocapqa.twist.detect import PaperParams, RobustParams
from mocapqa.twist.inject import InjectionTruth, inject_twist_errors
from mocapqa.twist.refine import refine_quats

__all__ = [
    "REAL_ERROR_TAKES",
    "RIGS",
    "BenchFile",
    "IntervalRecord",
    "MethodResult",
    "TwistBenchResult",
    "find_bench_files",
    "interval_records",
    "rig_of",
    "run_twist_bench",
    "seeded_injections",
    "speed_frames_per_s",
]

# Rig families reported separately, by corpus folder.
RIGS = ("cmu", "iclone", "bandai")
REAL_ERROR_TAKES = ("005_05.bvh",)
"""Corpus takes with real twist errors: never injected into, never used to choose anything."""


@dataclass(frozen=True, slots=True)
class IntervalRecord:
    """One reported interval of the benchmark.

    Parameters
    ----------
    rig : str
    held_out : bool
    take : str
        File name.
    features : tuple of float
        Confidence features (:data:`mocapqa.twist.intervals.FEATURES`).
    confidence : float
        Calibrated probability given by the shipped calibration.
    right : bool
        Whether applying it alone is right (see the module notes).
    """

    rig: str
    held_out: bool
    take: str
    features: tuple[float, ...]
    confidence: float
    right: bool


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
    per_take : dict
        ``(rig, held_out, take)`` → [frames succeeded, error frames], for bootstrap intervals.
    spill : dict
        ``(rig, held_out)`` → largest change of a target joint on its non-injected frames, °.
    records : list of IntervalRecord
        Every interval reported on the injected and the clean takes.
    ends : dict
        ``(rig, held_out)`` → [intervals injected at an end of the take, detected, corrected]
        (with ``ends`` injections; see :func:`run_twist_bench`).
    """

    before: dict[tuple[str, bool, str, str], list[np.ndarray]] = field(default_factory=dict)
    after: dict[tuple[str, bool, str, str], list[np.ndarray]] = field(default_factory=dict)
    clean: dict[tuple[str, bool], list[CleanChange]] = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)
    frames: dict[str, int] = field(default_factory=dict)
    per_take: dict[tuple[str, bool, str], list[int]] = field(default_factory=dict)
    spill: dict[tuple[str, bool], float] = field(default_factory=dict)
    records: list[IntervalRecord] = field(default_factory=list)
    ends: dict[tuple[str, bool], list[int]] = field(default_factory=dict)

    def end_counts(self, rigs: Sequence[str] = RIGS, held_out: bool | None = None) -> list[int]:
        """[injected, detected, corrected] intervals at an end of the take over the selection."""
        rows = [v for (rig, hold), v in self.ends.items()
                if rig in rigs and (held_out is None or hold == held_out)]  # fmt: skip
        return [sum(v[k] for v in rows) for k in range(3)]

    def bootstrap_fsr(
        self,
        rigs: Sequence[str] = RIGS,
        held_out: bool | None = None,
        samples: int = 1000,
        seed: int = 0,
    ) -> tuple[float, float]:
        """95 % bootstrap interval of the FSR, resampling takes (not frames)."""
        counts = np.array(
            [v for (rig, hold, _), v in self.per_take.items()
             if rig in rigs and (held_out is None or hold == held_out) and v[1] > 0]
        )  # fmt: skip
        if len(counts) == 0:
            return 0.0, 1.0
        rng = np.random.default_rng(seed)
        picks = rng.integers(0, len(counts), size=(samples, len(counts)))
        rates = counts[picks, 0].sum(axis=1) / counts[picks, 1].sum(axis=1)
        low, high = np.quantile(rates, [0.025, 0.975])
        return float(low), float(high)

    def max_spill(self, rigs: Sequence[str] = RIGS, held_out: bool | None = None) -> float:
        """Largest spill onto non-injected frames of the target joints, degrees."""
        return max(
            (v for (rig, hold), v in self.spill.items()
             if rig in rigs and (held_out is None or hold == held_out)),
            default=0.0,
        )  # fmt: skip

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
        if rig is not None and path.name not in REAL_ERROR_TAKES:
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


def interval_records(
    analysis: TwistAnalysis,
    truth_offsets: FloatArray | None,
    bench_file: BenchFile,
) -> list[IntervalRecord]:
    """Each interval of ``analysis`` labelled right or wrong against the injected offsets
    (parent joint columns of ``truth_offsets``, shape (F, J), radians; None: a clean take, where
    every interval is wrong)."""
    out = []
    for interval, found in zip(analysis.intervals, analysis.found, strict=True):
        if not found.features:
            continue
        rows = slice(interval.start_frame, interval.end_frame + 1)
        parent = analysis.chains[found.chain].chain.parent
        applied = analysis.detected_offsets_rad[rows, found.chain]
        injected = np.zeros_like(applied) if truth_offsets is None else truth_offsets[rows, parent]
        before = np.abs(wrap_angle(injected))
        after = np.abs(wrap_angle(injected - applied))
        right = bool(
            before.sum() > 0
            and after.sum() <= 0.2 * before.sum()
            and np.max(after - before) <= np.deg2rad(1.0)
        )
        out.append(
            IntervalRecord(bench_file.rig, bench_file.held_out, bench_file.path.name,
                           found.features, interval.confidence, right)
        )  # fmt: skip
    return out


def _count_ends(
    counts: list[int], analysis: TwistAnalysis, truth: InjectionTruth, corrected: Motion, ends: str
) -> None:
    """Add the injected intervals at an end of the take to ``counts`` ([injected, detected,
    corrected]); ``corrected`` is the corrupted take (the refined one is in ``analysis``)."""
    n_frames = truth.error_mask.shape[0]
    for target in truth.targets:
        joint = analysis.joint_names[target]
        mine = [i for i in truth.intervals if i.joint == joint]
        if not mine:
            continue
        end = (
            max(mine, key=lambda i: i.end_frame)
            if ends == "tail"
            else min(mine, key=lambda i: i.start_frame)
        )
        if ends == "tail" and end.end_frame != n_frames - 1:
            continue
        rows = slice(end.start_frame, end.end_frame + 1)
        covered = np.zeros(n_frames, dtype=bool)
        for interval in analysis.intervals:
            if interval.joint == joint:
                covered[interval.start_frame : interval.end_frame + 1] = True
        before = rotation_errors_deg(truth.clean_quats[rows, target], corrected.quats[rows, target])
        after = rotation_errors_deg(
            truth.clean_quats[rows, target], analysis.refined.quats[rows, target]
        )
        counts[0] += 1
        counts[1] += int(2 * np.sum(covered[rows]) >= end.end_frame - end.start_frame + 1)
        counts[2] += int(after.sum() <= 0.2 * before.sum())


def seeded_injections(
    motion: Motion,
    bench_file: BenchFile,
    seed: int,
    repeats: int,
    inject: Callable[[Motion, np.random.Generator], tuple[Motion, InjectionTruth]],
) -> Iterator[tuple[int, Motion, InjectionTruth]]:
    """Errors injected into a take ``repeats`` times by ``inject``, each seeded by ``(seed,
    crc32(file name), repeat)``: ``(repeat, corrupted, truth)``; an injection the take is too
    short for (an InputError) is left out."""
    name_key = zlib.crc32(bench_file.path.name.encode())
    for repeat in range(repeats):
        rng = np.random.default_rng((seed, name_key, repeat))
        try:
            corrupted, truth = inject(motion, rng)
        except InputError:
            continue
        yield repeat, corrupted, truth


def _score_targets(
    result: MethodResult, bench_file: BenchFile, corrupted: Motion, truth: InjectionTruth,
    refined: Motion, counts: list[int],
) -> None:  # fmt: skip
    """Add the rotation errors of each injected target before and after the refinement, the
    corrected frames (``counts``: [corrected, error frames] of the take) and the largest change
    outside the errors to ``result``."""
    group = (bench_file.rig, bench_file.held_out)
    for k, target in enumerate(truth.targets):
        rows = truth.error_mask[:, target]
        key = (bench_file.rig, bench_file.held_out, truth.sides[k], truth.segments[k])
        clean_rows = truth.clean_quats[rows, target]
        before = rotation_errors_deg(clean_rows, corrupted.quats[rows, target])
        after = rotation_errors_deg(clean_rows, refined.quats[rows, target])
        result.before.setdefault(key, []).append(before)
        result.after.setdefault(key, []).append(after)
        counts[0] += int(np.sum(after <= 0.2 * before))
        counts[1] += len(before)
        spill = rotation_errors_deg(truth.clean_quats[~rows, target], refined.quats[~rows, target])
        result.spill[group] = max(result.spill.get(group, 0.0), float(spill.max(initial=0.0)))


def _score_clean(
    result: MethodResult, bench_file: BenchFile, motion: Motion, method: str,
    params: RobustParams | PaperParams | None, apply: str,
) -> None:  # fmt: skip
    """Add the method's intervals, time and change on the take as recorded to ``result``."""
    group = (bench_file.rig, bench_file.held_out)
    start = time.perf_counter()
    analysis = analyze_twist(motion, method, params=params, apply=apply)
    elapsed = time.perf_counter() - start
    result.records += interval_records(analysis, None, bench_file)
    result.seconds[bench_file.rig] = result.seconds.get(bench_file.rig, 0.0) + elapsed
    result.frames[bench_file.rig] = result.frames.get(bench_file.rig, 0) + motion.n_frames
    has_rotation = np.array([bool(motion.skeleton.rotation_order(j)) for j in
                             range(motion.skeleton.n_joints)])  # fmt: skip
    mask = np.broadcast_to(has_rotation, motion.quats.shape[:2])
    change = clean_change(motion.quats, analysis.refined.quats, 1.0, mask)
    result.clean.setdefault(group, []).append(change)


def run_twist_bench(
    files: Sequence[BenchFile],
    methods: dict[str, tuple[str, RobustParams | PaperParams | None]],
    seed: int = 0,
    repeats: int = 2,
    on_file: Callable[[BenchFile], None] | None = None,
    apply: str = "confident",
    kind: str = "level",
    ends: str = "",
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
    apply : str
        Which intervals the refinement applies (see :func:`mocapqa.twist.analysis.analyze_twist`).
    kind : {"level", "burst", "cluster"}
        The injected error shape (see :func:`mocapqa.twist.inject.inject_twist_errors`).
    ends : {"", "head", "tail"}
        Force one level shift per target to start on the first frame of motion or to end on
        the last frame. Each such interval is *detected* when an interval reported on its
        joint (applied or not) covers at least half of its frames, and *corrected* when the
        refinement leaves at most 20 % of its summed rotation error.

    Returns
    -------
    TwistBenchResult
    """
    results = {label: MethodResult() for label in methods}
    n_injections = 0
    for bench_file in files:
        motion = read_bvh(bench_file.path)
        inject = functools.partial(inject_twist_errors, kind=kind, ends=ends)
        injected = [
            (corrupted, truth)
            for _, corrupted, truth in seeded_injections(motion, bench_file, seed, repeats, inject)
        ]
        n_injections += len(injected)
        take_key = (bench_file.rig, bench_file.held_out, bench_file.path.name)
        group = (bench_file.rig, bench_file.held_out)
        for label, (method, params) in methods.items():
            result = results[label]
            counts = result.per_take.setdefault(take_key, [0, 0])
            for corrupted, truth in injected:
                analysis = analyze_twist(corrupted, method, params=params, apply=apply)
                result.records += interval_records(analysis, truth.offsets_rad, bench_file)
                if ends:
                    _count_ends(result.ends.setdefault(group, [0, 0, 0]), analysis, truth,
                                corrected=corrupted, ends=ends)  # fmt: skip
                _score_targets(result, bench_file, corrupted, truth, analysis.refined, counts)
            _score_clean(result, bench_file, motion, method, params, apply)
        if on_file is not None:
            on_file(bench_file)
    return TwistBenchResult(results, len(files), n_injections)
