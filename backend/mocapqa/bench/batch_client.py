"""The batch client's own cost per take: hashing, storing and the row, with an empty analysis.

A cluster of many workers is only as fast as the one client that hashes each take, stores its
row and run, and writes its result line. ``mocapqa bench batch`` runs a batch whose task does no
analysis (:func:`empty_analysis` returns a real run summary at once), so what remains is the
client's work per take; with a Dask engine it also pays for submitting and collecting tasks.
"""

from __future__ import annotations

import contextlib
import socket
import subprocess
import sys
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["ClientCost", "empty_analysis", "separate_cluster"]


def empty_analysis(
    summary: dict[str, Any],
    path: str,
    options: dict[str, Any],
    take_id: str,
    run_id: str,
    data_dir: str | None,
) -> dict[str, Any]:
    """A batch task that analyses nothing: the outcome of a done take with ``summary``.

    Parameters
    ----------
    summary : dict
        A real run summary (of any take), returned as this take's.
    path, options, take_id, run_id, data_dir
        As :func:`mocapqa.jobs.take_task.analyse_path`; only the path and the id are used.
    """
    name = Path(path).name
    qa = summary["qa"]
    return {
        "status": "done",
        "take": {
            "id": take_id,
            "name": name,
            "format": "bvh",
            "kind": "motion",
            "size_bytes": 0,
            "n_frames": int(qa["n_frames"]),
            "fps": float(summary["fps"]),
            "n_joints": int(summary["n_joints"]),
            "file_name": name,
        },
        "summary": summary,
        "time_s": 0.0,
    }


@dataclass(frozen=True)
class ClientCost:
    """What the client spent on a batch of empty tasks.

    Attributes
    ----------
    takes : int
        Takes done.
    cpu_s, wall_s : float
        This process's CPU time and the wall-clock time, seconds.
    """

    takes: int
    cpu_s: float
    wall_s: float

    @property
    def cpu_ms_per_take(self) -> float:
        """Client CPU per take, milliseconds."""
        return 1000 * self.cpu_s / max(1, self.takes)


@contextlib.contextmanager
def separate_cluster(
    workers: int = 2,
    env: Mapping[str, str] | None = None,
    worker_prefix: Sequence[str] = (),
) -> Iterator[str]:
    """A ``dask scheduler`` and a ``dask worker`` of ``workers`` processes, each a process of
    its own (as on a real cluster, so the client's process CPU is the client's alone); yields
    the scheduler's address and stops both after.

    Parameters
    ----------
    workers : int
        Worker processes.
    env : mapping, optional
        Their environment (this process's when None).
    worker_prefix : sequence of str
        A command the worker is started under (``unshare …``, to hide the client's disk).
    """
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = int(sock.getsockname()[1])
    address = f"tcp://127.0.0.1:{port}"
    dask = str(Path(sys.executable).with_name("dask"))
    worker = [dask, "worker", address, "--nworkers", str(workers), "--nthreads", "1",
              "--no-dashboard"]  # fmt: skip
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    processes = [
        subprocess.Popen(
            [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
            **quiet,  # type: ignore[call-overload]
        ),
        subprocess.Popen([*worker_prefix, *worker], **quiet),  # type: ignore[call-overload]
    ]
    try:
        yield address
    finally:
        for process in reversed(processes):
            process.terminate()
        for process in reversed(processes):
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
