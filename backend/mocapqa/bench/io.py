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
  The readers take turns in blocks of consecutive runs, so that a busy spell on the machine
  falls on both alike while each is timed in its steady state, as in a loop over files. The
  first run of each block, right after the other reader, pays for caches and predictors the
  other reader left cold (~1.5 ms here, a fifth of ours and a twentieth of pybvh's); its best
  is reported beside the headline.
"""

from __future__ import annotations

import importlib
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import format_bvh, write_bvh
from mocapqa.kinematics.forward import end_site_positions, forward_kinematics

__all__ = [
    "FileTiming",
    "IoBenchParams",
    "ReaderComparison",
    "Throughput",
    "best_time_s",
    "info_process_time_s",
    "pybvh_comparison",
    "scratch_folder",
    "time_file",
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
        Consecutive runs of one reader before the other takes its turn, in the pybvh
        comparison.
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
        Best over the first run of each block, right after the other reader ran.
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


def pybvh_comparison(path: Path, repeats: int, block_runs: int) -> ReaderComparison | None:
    """Time read + positions of joints and End Sites, ours against pybvh's, in turns.

    Parameters
    ----------
    path : Path
        The BVH file.
    repeats : int
        Timed runs of each reader (rounded up to whole blocks).
    block_runs : int
        Consecutive runs of one reader per turn.

    Returns
    -------
    ReaderComparison or None
        None when pybvh (the ``bench`` extra) is not installed.
    """
    try:
        pybvh = importlib.import_module("pybvh")
    except ImportError:
        return None

    def theirs() -> None:
        pybvh.read_bvh_file(str(path)).node_positions()

    def ours() -> None:
        _read_fk(path)

    ours()
    theirs()  # so that our first block, too, starts right after pybvh
    ours_runs: list[list[float]] = []
    theirs_runs: list[list[float]] = []
    for _ in range(-(-repeats // block_runs)):
        ours_runs.append([best_time_s(ours, 1) for _ in range(block_runs)])
        theirs_runs.append([best_time_s(theirs, 1) for _ in range(block_runs)])
    return ReaderComparison(
        ours_s=min(map(min, ours_runs)),
        theirs_s=min(map(min, theirs_runs)),
        ours_first_s=min(block[0] for block in ours_runs),
        theirs_first_s=min(block[0] for block in theirs_runs),
    )


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
