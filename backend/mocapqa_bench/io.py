"""BVH input/output throughput: read, read + forward kinematics, and write.

Conventions
-----------
* Every figure is the best of ``repeats`` runs (``time.perf_counter``), after one untimed
  warm-up read of each file; MB are 10⁶ bytes of the file as stored (for writes, as written).
* Figures are for a warm process, as in a server or a batch (imports done, files in the page
  cache). The cold single-file case is measured separately as the wall time of a whole
  ``mocapqa info`` process.
* The pybvh comparison times ``pybvh.read_bvh_file`` + ``node_positions()`` (joints and End
  Sites) against :func:`~mocapqa.io.bvh.read_bvh` + forward kinematics + End Site positions.
  The readers, and the largest Bandai read, take turns of consecutive runs
  (:func:`timed_in_turns`), so that a slow spell on the machine falls on all alike while each
  is timed in its steady state, as in a loop over files. The first run of each turn, right
  after the other reader, pays for caches and predictors the other reader left cold (~1 ms
  here, a sixth of ours and a twentieth of pybvh's); its best is reported beside the headline.
"""

from __future__ import annotations

import importlib
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import format_bvh, write_bvh
from mocapqa.kinematics.forward import end_site_positions, forward_kinematics

__all__ = [
    "FileTiming",
    "HeadlineTimes",
    "IoBenchParams",
    "ReaderComparison",
    "Throughput",
    "best_time_s",
    "headline_times",
    "info_process_time_s",
    "pybvh_work",
    "scratch_folder",
    "time_file",
    "timed_in_turns",
    "total_throughput",
    "warm_up",
]


@dataclass(frozen=True, slots=True)
class IoBenchParams:
    """Parameters of the I/O benchmark.

    Parameters
    ----------
    repeats : int
        Timed runs per measurement; the best is kept.
    max_files : int or None
        Benchmark only the first files (sorted by path); all when None.
    info_runs : int
        Runs of the ``mocapqa info`` process; the best is kept.
    headline_repeats : int
        Timed runs of the figures with targets (the largest Bandai read, and each reader of
        the pybvh comparison); the best of each is kept.
    block_runs : int
        Consecutive runs of one of those works before the next takes its turn.
    """

    repeats: int = 3
    max_files: int | None = None
    info_runs: int = 5
    headline_repeats: int = 100
    block_runs: int = 10

    def __post_init__(self) -> None:
        counts = (self.repeats, self.info_runs, self.headline_repeats, self.block_runs)
        if min(counts) < 1:
            raise InputError(
                "Expected repeats, info_runs, headline_repeats and block_runs >= 1, got "
                + ", ".join(map(str, counts))
            )
        if self.max_files is not None and self.max_files < 1:
            raise InputError(f"Expected max_files >= 1 or None, got {self.max_files}")


@dataclass(frozen=True, slots=True)
class FileTiming:
    """Best times for one BVH file.

    Parameters
    ----------
    path : Path
    n_bytes : int
        Size of the file.
    n_written_bytes : int
        Size of the file as written back.
    n_frames : int
    read_s, read_fk_s, write_s : float
        Seconds to read; to read and compute world positions of joints and End Sites; to
        format and write the take.
    """

    path: Path
    n_bytes: int
    n_written_bytes: int
    n_frames: int
    read_s: float
    read_fk_s: float
    write_s: float


@dataclass(frozen=True, slots=True)
class Throughput:
    """An amount of work and the time it took.

    Parameters
    ----------
    label : str
    n_bytes : int
    n_frames : int
    seconds : float
    """

    label: str
    n_bytes: int
    n_frames: int
    seconds: float

    @property
    def frames_per_s(self) -> float:
        """Frames per second of wall time."""
        return self.n_frames / self.seconds if self.seconds > 0 else float("inf")

    @property
    def mb_per_s(self) -> float:
        """10⁶ bytes per second of wall time."""
        return self.n_bytes / 1e6 / self.seconds if self.seconds > 0 else float("inf")


def best_time_s(work: Callable[[], object], repeats: int) -> float:
    """The shortest of ``repeats`` wall times of ``work()``, in seconds."""
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        work()
        best = min(best, time.perf_counter() - start)
    return best


def warm_up(files: Sequence[Path]) -> None:
    """Read and format each file once, untimed (imports, page cache)."""
    for path in files:
        format_bvh(read_bvh(path))


def _read_fk(path: Path) -> None:
    motion = read_bvh(path)
    world_quats, world_positions = forward_kinematics(motion)
    end_site_positions(motion, world_quats, world_positions)


def time_file(path: Path, repeats: int, scratch: Path) -> FileTiming:
    """Time reading, reading + FK, and writing one BVH file.

    Parameters
    ----------
    path : Path
        The BVH file.
    repeats : int
        Runs per measurement (best kept).
    scratch : Path
        A folder for the written copy.
    """
    motion = read_bvh(path)
    out = scratch / path.name
    read_s = best_time_s(lambda: read_bvh(path), repeats)
    read_fk_s = best_time_s(lambda: _read_fk(path), repeats)
    write_s = best_time_s(lambda: write_bvh(out, motion), repeats)
    return FileTiming(
        path=path,
        n_bytes=path.stat().st_size,
        n_written_bytes=out.stat().st_size,
        n_frames=motion.n_frames,
        read_s=read_s,
        read_fk_s=read_fk_s,
        write_s=write_s,
    )


def total_throughput(timings: Sequence[FileTiming]) -> list[Throughput]:
    """Corpus totals: read, read + FK and write, one row each."""
    n_bytes = sum(t.n_bytes for t in timings)
    n_frames = sum(t.n_frames for t in timings)
    return [
        Throughput("read", n_bytes, n_frames, sum(t.read_s for t in timings)),
        Throughput("read + FK", n_bytes, n_frames, sum(t.read_fk_s for t in timings)),
        Throughput(
            "write", sum(t.n_written_bytes for t in timings), n_frames,
            sum(t.write_s for t in timings),
        ),
    ]  # fmt: skip


@dataclass(frozen=True, slots=True)
class ReaderComparison:
    """Best seconds of mocapqa and pybvh for read + positions of joints and End Sites.

    Parameters
    ----------
    ours_s, theirs_s : float
        Best over every run: each reader in its steady state.
    ours_first_s, theirs_first_s : float
        Best over the first run of each turn, right after the other reader ran.
    """

    ours_s: float
    theirs_s: float
    ours_first_s: float
    theirs_first_s: float

    @property
    def ratio(self) -> float:
        """pybvh's time over ours, steady state."""
        return self.theirs_s / self.ours_s

    @property
    def first_ratio(self) -> float:
        """pybvh's time over ours, first runs after the other reader."""
        return self.theirs_first_s / self.ours_first_s


@dataclass(frozen=True, slots=True)
class HeadlineTimes:
    """The figures with targets: the pybvh comparison and the largest Bandai read.

    Parameters
    ----------
    comparison : ReaderComparison or None
        None without the CMU walk or without pybvh.
    bandai_read_s : float or None
        Best seconds to read the largest Bandai file; None without one.
    """

    comparison: ReaderComparison | None
    bandai_read_s: float | None


def pybvh_work(path: Path) -> Callable[[], object] | None:
    """pybvh's read + positions of joints and End Sites of ``path``; None without pybvh."""
    try:
        pybvh = importlib.import_module("pybvh")
    except ImportError:
        return None
    return lambda: pybvh.read_bvh_file(str(path)).node_positions()


def timed_in_turns(
    works: Mapping[str, Callable[[], object]], repeats: int, block_runs: int
) -> dict[str, list[list[float]]]:
    """Seconds of every run of each work, the works taking turns of ``block_runs`` runs.

    The machine's speed changes in spells of a second or so (a fixed workload here takes
    3.1 ms in some and 4.6 ms in others), so runs of one work in a row could all fall in a slow
    spell; in turns, the runs of every work spread over the whole measurement.

    Parameters
    ----------
    works : mapping of str to callable
        The works, in turn order; each runs once first, untimed.
    repeats : int
        Timed runs of each work (rounded up to whole turns).
    block_runs : int
        Consecutive runs per turn.

    Returns
    -------
    dict of str to list of list of float
        Per work, the seconds of each run, turn by turn.
    """
    for work in works.values():
        work()
    times: dict[str, list[list[float]]] = {name: [] for name in works}
    for _ in range(-(-repeats // block_runs)):
        for name, work in works.items():
            times[name].append([best_time_s(work, 1) for _ in range(block_runs)])
    return times


def headline_times(
    walk: Path | None, bandai: Path | None, repeats: int, block_runs: int
) -> HeadlineTimes:
    """Time the figures with targets, in turns (see :func:`timed_in_turns`).

    Parameters
    ----------
    walk : Path or None
        The CMU walk, for read + FK against pybvh.
    bandai : Path or None
        The largest Bandai file, for the read throughput.
    repeats, block_runs : int
        Timed runs of each work, and runs per turn.
    """
    works: dict[str, Callable[[], object]] = {}
    if bandai is not None:
        works["bandai"] = lambda: read_bvh(bandai)
    theirs = pybvh_work(walk) if walk is not None else None
    if walk is not None and theirs is not None:
        # This order puts each reader's turn right after the other's.
        works["pybvh"] = theirs
        works["ours"] = lambda: _read_fk(walk)
    times = timed_in_turns(works, repeats, block_runs)
    comparison = None
    if "ours" in times:
        comparison = ReaderComparison(
            ours_s=min(map(min, times["ours"])),
            theirs_s=min(map(min, times["pybvh"])),
            ours_first_s=min(turn[0] for turn in times["ours"]),
            theirs_first_s=min(turn[0] for turn in times["pybvh"]),
        )
    bandai_s = min(map(min, times["bandai"])) if "bandai" in times else None
    return HeadlineTimes(comparison, bandai_s)


def info_process_time_s(path: Path, runs: int) -> float:
    """Best wall time in seconds of a whole ``mocapqa info PATH`` process."""
    script = Path(sys.executable).with_name("mocapqa")
    command = [str(script)] if script.is_file() else [sys.executable, "-m", "mocapqa.cli.main"]
    if not script.is_file() and shutil.which("mocapqa"):
        command = ["mocapqa"]

    def run() -> None:
        subprocess.run([*command, "info", str(path)], check=True, capture_output=True)

    return best_time_s(run, runs)


def scratch_folder() -> tempfile.TemporaryDirectory[str]:
    """A temporary folder for written copies (removed when closed)."""
    return tempfile.TemporaryDirectory(prefix="mocapqa-bench-io-")
