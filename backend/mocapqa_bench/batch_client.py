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
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "ClientCost",
    "client_cost",
    "empty_analysis",
    "print_client_figures",
    "separate_cluster",
]


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


def client_cost(folder: Path, summary: dict[str, Any], scratch: Path, engine: Any = None) -> Any:
    """Run a batch of ``folder`` with :func:`empty_analysis` into a new SQLite store.

    Parameters
    ----------
    folder : Path
        The takes (hashed and stored as a real batch would).
    summary : dict
        The run summary every take gets.
    scratch : Path
        A new folder for the store.
    engine : Engine, optional
        A Dask engine (its local cluster's scheduler runs in this process, so its CPU is
        counted); None runs the empty tasks in this process.
    """
    import functools

    from mocapqa.jobs.batch import run_batch
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore

    scratch.mkdir(parents=True, exist_ok=True)
    repository = Repository(f"sqlite:///{scratch / 'db.sqlite3'}")
    task = functools.partial(empty_analysis, summary)
    try:
        clock, cpu = time.perf_counter(), time.process_time()
        counts = run_batch(
            [folder], ShootStore(repository.engine), AnalysisOptions(), lambda row: None,
            engine, None, task=task,
        )  # fmt: skip
        return ClientCost(counts.done, time.process_time() - cpu, time.perf_counter() - clock)
    finally:
        repository.close()


def print_client_figures(console: Any, folder: Path, sample: str, root: Path) -> None:
    """Print the client's CPU per take with an empty analysis, alone and on 2 Dask workers."""
    from mocapqa.jobs.engine import Engine
    from mocapqa.jobs.take_task import analyse_path, content_sha256
    from mocapqa.pipeline.options import AnalysisOptions

    summary = analyse_path(sample, AnalysisOptions().to_json(), "0" * 32, "1" * 32, None)
    alone = client_cost(folder, summary["summary"], root / "client-alone")
    with separate_cluster(workers=2) as address, Engine(scheduler=address) as engine:
        engine.client().wait_for_workers(2, timeout=120)
        on_dask = client_cost(folder, summary["summary"], root / "client-dask", engine)
    cpu = time.process_time()
    for path in sorted(folder.iterdir()):
        content_sha256(path)
    hashing_ms = 1000 * (time.process_time() - cpu) / max(1, alone.takes)
    console.print(
        f"client CPU per take, empty analysis ({alone.takes} takes; hash, store, row; of which "
        f"hashing the take's bytes {hashing_ms:.2f} ms): "
        f"tasks in the client's process {alone.cpu_ms_per_take:.2f} ms; sent to 2 Dask "
        f"workers (scheduler and workers in processes of their own) "
        f"{on_dask.cpu_ms_per_take:.2f} ms (target ≤ 1 ms)",
        highlight=False,
    )
