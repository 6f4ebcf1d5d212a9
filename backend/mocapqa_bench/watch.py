"""A command run as its own process, with its peak memory and that of its child processes
(a batch's Dask workers) sampled while it runs, and the CPU time of the whole tree."""

from __future__ import annotations

import os
import resource
import subprocess
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["Watched", "run_watched"]


@dataclass(frozen=True, slots=True)
class Watched:
    """What :func:`run_watched` measured.

    Attributes
    ----------
    wall_s : float
        Seconds from start to exit.
    cpu_s : float
        User + system CPU seconds of the process and every child it waited for.
    peak_mb : float
        Largest resident memory of the process itself (MB, sampled).
    children_peak_mb : float
        Largest resident memory of any one child process (MB, sampled; 0 without children).
    returncode : int
    stderr : str
        The last 4,000 characters of its error output.
    """

    wall_s: float
    cpu_s: float
    peak_mb: float
    children_peak_mb: float
    returncode: int
    stderr: str


def _cpu_of_children() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_watched(
    command: Sequence[str], env: dict[str, str] | None = None, every_s: float = 0.05
) -> Watched:
    """Run ``command`` to its end, sampling resident memory every ``every_s`` seconds.

    Parameters
    ----------
    command : sequence of str
        The program and its arguments.
    env : dict, optional
        Variables added to this process's environment.
    every_s : float
        Sampling period (seconds).
    """
    import psutil  # type: ignore[import-untyped]

    cpu_before = _cpu_of_children()
    clock = time.perf_counter()
    with subprocess.Popen(
        list(command),
        env={**os.environ, **(env or {})},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    ) as process:
        watched = psutil.Process(process.pid)
        peak = children_peak = 0.0
        errors: list[str] = []
        reader = threading.Thread(target=lambda: errors.append(process.stderr.read()))  # type: ignore[union-attr]
        reader.start()
        while process.poll() is None:
            try:
                peak = max(peak, watched.memory_info().rss / 2**20)
                for child in watched.children(recursive=True):
                    children_peak = max(children_peak, _rss_mb(child))
            except psutil.Error:  # it ended between the poll and the sample
                pass
            time.sleep(every_s)
        reader.join()
    return Watched(
        wall_s=time.perf_counter() - clock,
        cpu_s=_cpu_of_children() - cpu_before,
        peak_mb=peak,
        children_peak_mb=children_peak,
        returncode=int(process.returncode),
        stderr="".join(errors)[-4000:],
    )


def _rss_mb(process: Any) -> float:
    import psutil

    try:
        return float(process.memory_info().rss) / 2**20
    except psutil.Error:
        return 0.0
