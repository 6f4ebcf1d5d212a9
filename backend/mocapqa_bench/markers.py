"""``mocapqa bench markers``, swap part: injected swaps on real C3D takes, false swaps and
spikes on clean ones, threshold choice leaving one file out, and speed.

Files: :data:`BENCH_FILES` under the corpus' ``c3d/`` folder, four full-body takes from four
systems (OptiTrack 50 Hz in metres, CMU/Vicon 120 Hz, Vicon 120 Hz with gaps, a c3d.org gait
sample at 50 Hz); the README calls the first three clean, and the check finds no swap in the
fourth.

Trials: per file and seed, :func:`mocapqa.markers.inject.inject_swaps` exchanges
:data:`SWAPS_PER_TRIAL` pairs of neighbouring markers (rigid mates, or the nearest marker) for
0.05–1 s each, in stretches where both are visible, and the whole swap check runs on the
changed take (pair statistics included). A swap is found when a reported swap names the same
two markers and its first and last frames are each within :data:`FRAME_TOLERANCE` frames of
the truth; every other reported swap is false. Clean figures are the swaps and spikes the
check reports on the unchanged takes, per 10,000 frames.

Choice (leave one file out): every file's trials and clean take are counted once under each
grid point of (``swap_misfit``, ``swap_gain``, ``swap_held``) (:func:`grid_table`); for each
file, the grid point with the best F1 on the other files' trials, among those with no false
swap on their clean takes, is applied to the held-out file, whose figures are reported.
``choose`` over all files gives the defaults of :class:`mocapqa.markers.params.MarkerParams`.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError
from mocapqa.io.c3d import read_c3d
from mocapqa.markers.check import check_markers
from mocapqa.markers.inject import InjectedSwap, inject_swaps
from mocapqa.markers.misfits import misfits, tolerances
from mocapqa.markers.params import MarkerParams
from mocapqa.markers.segments import mates, pair_stats
from mocapqa.markers.spikes import find_spikes
from mocapqa.markers.swaps import Swap, find_swaps

__all__ = [
    "BENCH_FILES",
    "FRAME_TOLERANCE",
    "GRID",
    "SWAPS_PER_TRIAL",
    "BenchTake",
    "Counts",
    "GridRow",
    "HeldOut",
    "best_point",
    "check_speed",
    "choose",
    "clean_flags",
    "grid_params",
    "grid_table",
    "leave_one_out",
    "load_takes",
    "spike_recall",
    "swap_figures",
    "swap_trials",
    "tiled_take",
]

BENCH_FILES = (
    "optitrack/kinematics_tennis_serve.c3d",
    "cmu/cmu_02_05.c3d",
    "vicon/nick_freeform_001.c3d",
    "btk/Eb015pr.c3d",
)
"""Corpus paths under ``c3d/`` of the takes the bench uses."""
SWAPS_PER_TRIAL = 2
"""Swaps injected per trial."""
FRAME_TOLERANCE = 2
"""Largest error of a found swap's first or last frame, frames."""
GRID = tuple((m, g, h) for m in (2.0, 2.5, 3.0, 4.0) for g in (0.35, 0.5) for h in (0.25, 0.5))
"""(``swap_misfit``, ``swap_gain``, ``swap_held``) points tried by :func:`choose`."""


@dataclass(frozen=True, slots=True)
class BenchTake:
    """A C3D take ready for the bench: positions ``(F, M, 3)`` in ``length_unit``."""

    name: str
    positions: FloatArray
    names: tuple[str, ...]
    fps: float
    length_unit: str


@dataclass(frozen=True, slots=True)
class Counts:
    """Injected-swap outcome counts; precision and recall are None when undefined."""

    injected: int = 0
    found: int = 0
    false: int = 0

    def __add__(self, other: Counts) -> Counts:
        return Counts(
            self.injected + other.injected, self.found + other.found, self.false + other.false
        )

    @property
    def recall(self) -> float | None:
        """Found over injected."""
        return self.found / self.injected if self.injected else None

    @property
    def precision(self) -> float | None:
        """Found over reported."""
        reported = self.found + self.false
        return self.found / reported if reported else None

    @property
    def f1(self) -> float:
        """Harmonic mean of precision and recall (0 when either is undefined or 0)."""
        p, r = self.precision, self.recall
        return 2 * p * r / (p + r) if p and r else 0.0


@dataclass(frozen=True, slots=True)
class HeldOut:
    """Figures of one held-out file under the parameters chosen on the others.

    Parameters
    ----------
    name : str
    swap_misfit, swap_gain, swap_held : float
        Chosen on the other files.
    counts : Counts
        Injected swaps, all reported swaps.
    confident : Counts
        The same counting only swaps at or above ``swap_confidence``.
    false_swaps_per_10k, spikes_per_10k : float
        On the clean take.
    """

    name: str
    swap_misfit: float
    swap_gain: float
    swap_held: float
    counts: Counts
    confident: Counts
    false_swaps_per_10k: float
    spikes_per_10k: float


def load_takes(corpus_dir: Path, files: Sequence[str] = BENCH_FILES) -> list[BenchTake]:
    """The bench takes, read through :func:`mocapqa.io.c3d.read_c3d`."""
    takes = []
    for name in files:
        points = read_c3d(corpus_dir / "c3d" / name).points
        takes.append(
            BenchTake(name, points.positions, points.names, points.fps, points.length_unit)
        )
    return takes


def _matches(swap: Swap, truth: InjectedSwap) -> bool:
    return (
        set(swap.indices) == {truth.a, truth.b}
        and abs(swap.start - truth.start) <= FRAME_TOLERANCE
        and abs(swap.end - truth.end) <= FRAME_TOLERANCE
    )


def _score(found: Sequence[Swap], truth: Sequence[InjectedSwap]) -> Counts:
    hits = sum(any(_matches(s, t) for s in found) for t in truth)
    false = sum(not any(_matches(s, t) for t in truth) for s in found)
    return Counts(len(truth), hits, false)


def _trial_takes(
    take: BenchTake, seeds: Sequence[int], params: MarkerParams
) -> list[tuple[FloatArray, list[InjectedSwap]]]:
    stats = pair_stats(take.positions, take.length_unit, params)
    return [
        inject_swaps(take.positions, np.random.default_rng(seed), stats, take.fps,
                     count=SWAPS_PER_TRIAL)
        for seed in seeds
    ]  # fmt: skip


def swap_trials(
    take: BenchTake, seeds: Sequence[int], grid: Sequence[MarkerParams]
) -> list[tuple[Counts, Counts]]:
    """Injected-swap counts of one take under each parameter set.

    Parameters
    ----------
    take : BenchTake
    seeds : sequence of int
        One trial of :data:`SWAPS_PER_TRIAL` swaps per seed.
    grid : sequence of MarkerParams
        Sets sharing their pair-statistics thresholds (``rigid_*``, ``segment_frames``).

    Returns
    -------
    list of (Counts, Counts)
        Per parameter set: all reported swaps, and only the confident ones.
    """
    if not grid:
        return []
    trials = _trial_takes(take, seeds, grid[0])
    totals = [(Counts(), Counts()) for _ in grid]
    for positions, truth in trials:
        stats = pair_stats(positions, take.length_unit, grid[0])
        for i, params in enumerate(grid):
            found = find_swaps(positions, take.names, stats, take.length_unit, params)
            sure = [s for s in found if s.confidence >= params.swap_confidence]
            totals[i] = (totals[i][0] + _score(found, truth), totals[i][1] + _score(sure, truth))
    return totals


def clean_flags(take: BenchTake, params: MarkerParams) -> tuple[float, float]:
    """Swaps and spikes the full check reports on an unchanged take, per 10,000 frames."""
    report = check_markers(take.positions, take.names, take.fps, take.length_unit, params)
    scale = 10_000 / take.positions.shape[0]
    return len(report.swaps) * scale, len(report.spikes) * scale


def grid_params(base: MarkerParams | None = None) -> list[MarkerParams]:
    """``base`` with each :data:`GRID` point's ``swap_misfit``, ``swap_gain`` and
    ``swap_held``."""
    base = base or MarkerParams()
    return [dataclasses.replace(base, swap_misfit=m, swap_gain=g, swap_held=h) for m, g, h in GRID]


@dataclass(frozen=True, slots=True)
class GridRow:
    """One take under one grid point: its trials' counts (all reported swaps, confident
    ones) and whether its clean take has no swap."""

    counts: Counts
    confident: Counts
    clean: bool


def grid_table(
    takes: Sequence[BenchTake], seeds: Sequence[int], grid: Sequence[MarkerParams]
) -> list[list[GridRow]]:
    """Every take's :class:`GridRow` under every grid point, ``[take][point]``."""
    table: list[list[GridRow]] = []
    for take in takes:
        stats = pair_stats(take.positions, take.length_unit, grid[0])
        rows = []
        for (counts, confident), params in zip(swap_trials(take, seeds, grid), grid, strict=True):
            found = find_swaps(take.positions, take.names, stats, take.length_unit, params)
            rows.append(GridRow(counts, confident, not found))
        table.append(rows)
    return table


def best_point(table: Sequence[Sequence[GridRow]], chosen_on: Sequence[int]) -> tuple[int, Counts]:
    """The grid point with the best pooled F1 over some takes.

    Parameters
    ----------
    table : sequence of sequence of GridRow
        ``[take][point]`` (:func:`grid_table`).
    chosen_on : sequence of int
        The takes (indices into ``table``) that choose.

    Returns
    -------
    index : int
        The point with the best F1 among those with no swap on these takes' clean takes (if
        none is clean, among all), the first in :data:`GRID` order on a tie.
    counts : Counts
        Its pooled counts over ``chosen_on``.
    """
    n_points = len(table[0])
    pooled = [sum((table[t][i].counts for t in chosen_on), Counts()) for i in range(n_points)]
    clean = [all(table[t][i].clean for t in chosen_on) for i in range(n_points)]
    best = min(range(n_points), key=lambda i: (not clean[i], -pooled[i].f1, i))
    return best, pooled[best]


def choose(
    takes: Sequence[BenchTake], seeds: Sequence[int], base: MarkerParams | None = None
) -> tuple[MarkerParams, Counts]:
    """The grid point with the best F1 over ``takes`` among those with no false swap on them.

    Returns
    -------
    params : MarkerParams
    counts : Counts
        Its pooled counts over ``takes``.
    """
    grid = grid_params(base)
    best, pooled = best_point(grid_table(takes, seeds, grid), range(len(takes)))
    return grid[best], pooled


def _held_out(
    takes: Sequence[BenchTake], table: Sequence[Sequence[GridRow]], grid: Sequence[MarkerParams]
) -> list[HeldOut]:
    held: list[HeldOut] = []
    for i, take in enumerate(takes):
        best, _ = best_point(table, [j for j in range(len(takes)) if j != i])
        params, row = grid[best], table[i][best]
        swaps, spikes = clean_flags(take, params)
        held.append(
            HeldOut(take.name, params.swap_misfit, params.swap_gain, params.swap_held,
                    row.counts, row.confident, swaps, spikes)
        )  # fmt: skip
    return held


def leave_one_out(
    takes: Sequence[BenchTake], seeds: Sequence[int], base: MarkerParams | None = None
) -> list[HeldOut]:
    """Figures of each take under the parameters :func:`choose` picks on the others."""
    grid = grid_params(base)
    return _held_out(takes, grid_table(takes, seeds, grid), grid)


def spike_recall(
    take: BenchTake,
    sizes_mm: Sequence[float],
    trials: int,
    seed: int = 0,
    params: MarkerParams | None = None,
) -> dict[float, float]:
    """Share of single-sample offsets found as spikes, per offset size.

    Each trial moves one sample of a random marker, at a frame where it and its two
    neighbours on each side are visible, by ``size`` mm in a random direction; it is found
    when a spike of that marker peaks within one frame of it.
    """
    p = params or MarkerParams()
    rng = np.random.default_rng(seed)
    scale = 1.0 / {"m": 1000.0, "cm": 10.0, "mm": 1.0, "in": 25.4}.get(take.length_unit, 1.0)
    present = np.isfinite(take.positions).all(-1)
    window = np.lib.stride_tricks.sliding_window_view(present, 5, axis=0).all(-1)
    frames, markers = np.nonzero(window)
    stats = pair_stats(take.positions, take.length_unit, p)
    mate_index = mates(stats, p.max_mates, p.mate_score)
    tolerance = tolerances(stats, take.length_unit, p)
    found: dict[float, float] = {}
    for size in sizes_mm:
        hits = 0
        for _ in range(trials):
            k = int(rng.integers(frames.size))
            frame, marker = int(frames[k]) + 2, int(markers[k])
            direction = rng.normal(size=3)
            moved = take.positions.copy()
            moved[frame, marker] += size * scale * direction / np.linalg.norm(direction)
            misfit = misfits(moved, mate_index, stats, tolerance)
            spikes = find_spikes(moved, take.names, take.fps, take.length_unit, p, misfit)
            hits += any(s.index == marker and abs(s.peak - frame) <= 1 for s in spikes)
        found[size] = hits / trials
    return found


def tiled_take(
    takes: Sequence[BenchTake], frames: int = 10_000, markers: int = 60
) -> tuple[FloatArray, tuple[str, ...]]:
    """A long take of ``frames`` × ``markers`` made of real ones, in millimetres.

    Each take is played forward then backward (so the tiling does not jump) until it is
    ``frames`` long; their markers are put side by side, each take moved 3 m along x from
    the previous one (two performers in one volume), and cut at ``markers``.

    Raises
    ------
    InputError
        If the takes hold fewer than ``markers`` markers.
    """
    columns: list[FloatArray] = []
    names: list[str] = []
    for k, take in enumerate(takes):
        scale = {"m": 1000.0, "cm": 10.0, "mm": 1.0, "in": 25.4}.get(take.length_unit, 1.0)
        cycle = np.concatenate([take.positions, take.positions[::-1]], axis=0) * scale
        repeats = -(-frames // cycle.shape[0])
        tiled = np.tile(cycle, (repeats, 1, 1))[:frames].copy()
        tiled[..., 0] += 3000.0 * k
        columns.append(tiled)
        names += [f"T{k}:{n}" for n in take.names]
        if len(names) >= markers:
            break
    if len(names) < markers:
        raise InputError(f"Expected takes with {markers} markers in all, got {len(names)}")
    return np.concatenate(columns, axis=1)[:, :markers], tuple(names[:markers])


def check_speed(
    takes: Sequence[BenchTake], frames: int = 10_000, markers: int = 60, repeats: int = 5
) -> tuple[float, float]:
    """Best wall and best CPU time of :func:`mocapqa.markers.check.check_markers` on a tiled
    take, seconds.

    The caller pins BLAS to one thread (numpy's own loops use one); the CPU time of the
    process is the figure to read on a busy machine, where the wall time also counts the
    waits for a core.
    """
    positions, names = tiled_take(takes, frames, markers)
    wall = cpu = float("inf")
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        check_markers(positions, names, 120.0, "mm")
        wall = min(wall, time.perf_counter() - start)
        cpu = min(cpu, time.process_time() - start_cpu)
    return wall, cpu


SPIKE_SIZES_MM = (10.0, 20.0, 30.0, 50.0)
"""Single-sample offsets :func:`swap_figures` injects, millimetres."""


def swap_figures(
    corpus_dir: Path, seeds: Sequence[int] = range(50), spike_trials: int = 40
) -> dict[str, object]:
    """Every figure of the swap and spike part of ``mocapqa bench markers``, JSON-ready.

    Parameters
    ----------
    corpus_dir : Path
        The corpus (its ``c3d/`` folder holds :data:`BENCH_FILES`).
    seeds : sequence of int
        One trial of :data:`SWAPS_PER_TRIAL` injected swaps per seed and file.
    spike_trials : int
        Single-sample offsets per size and file.

    Returns
    -------
    dict
        ``held_out``: per file, the parameters chosen on the others and its figures;
        ``chosen``: the parameters chosen on all files and their pooled counts;
        ``spikes``: per file, spike recall per offset size and clean spikes per 10,000
        frames under the defaults; ``speed``: wall and CPU seconds of the full check of a
        10,000-frame, 60-marker take.
    """
    takes = load_takes(corpus_dir)

    def counts(c: Counts) -> dict[str, object]:
        return {"injected": c.injected, "found": c.found, "false": c.false,
                "precision": c.precision, "recall": c.recall}  # fmt: skip

    grid = grid_params()
    table = grid_table(takes, seeds, grid)
    held = [
        {"file": h.name, "swap_misfit": h.swap_misfit, "swap_gain": h.swap_gain,
         "swap_held": h.swap_held, "all": counts(h.counts), "confident": counts(h.confident),
         "clean_swaps_per_10k": h.false_swaps_per_10k, "clean_spikes_per_10k": h.spikes_per_10k}
        for h in _held_out(takes, table, grid)
    ]  # fmt: skip
    best, pooled = best_point(table, range(len(takes)))
    params = grid[best]
    spikes = []
    for take in takes:
        _, per_10k = clean_flags(take, MarkerParams())
        recall = spike_recall(take, SPIKE_SIZES_MM, spike_trials)
        spikes.append({"file": take.name, "clean_spikes_per_10k": per_10k,
                       "recall": {str(k): v for k, v in recall.items()}})  # fmt: skip
    wall, cpu = check_speed(takes[1:3])
    return {
        "held_out": held,
        "chosen": {"swap_misfit": params.swap_misfit, "swap_gain": params.swap_gain,
                   "swap_held": params.swap_held, **counts(pooled)},
        "spikes": spikes,
        "speed": {"frames": 10_000, "markers": 60, "wall_s": wall, "cpu_s": cpu},
    }  # fmt: skip
