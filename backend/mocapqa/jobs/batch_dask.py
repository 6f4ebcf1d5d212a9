"""A batch's takes on a Dask cluster: sent in chunks, a bounded number in flight.

Each chunk is one Dask task that runs the per-take function on several takes
(:data:`CHUNK_TAKES` in a large batch, fewer in a small one: :func:`chunk_size`), as paths
(``task``: the workers read the client's files and write the data folder) or as bytes
(:func:`mocapqa.jobs.take_task.analyse_sent`, with at most :data:`SENT_BYTES_IN_FLIGHT` of
takes on their way at once). Each answered take is handed to the batch (:class:`BatchSink`),
which stores it or lists it as failed.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

from mocapqa.jobs.engine import Engine
from mocapqa.jobs.sent_files import SentFiles, pack
from mocapqa.jobs.take_task import analyse_sent
from mocapqa.store.stamps import new_id

__all__ = [
    "CHUNK_TAKES",
    "SENT_BYTES_IN_FLIGHT",
    "BatchSink",
    "InFlight",
    "Task",
    "chunk_size",
    "run_chunks",
]

CHUNK_TAKES = 4
"""Takes per Dask task in a large batch. A task costs the client, scheduler and worker about
9 ms of CPU beyond the take's own work (about 95 ms): one take per task made the Dask path
about 10 % dearer than a loop, four per task make it about 2 % (docs/batch.md)."""

SENT_BYTES_IN_FLIGHT = 256 * 1024 * 1024
"""Most bytes of takes sent to workers and not yet answered, when the workers do not share
the client's files (one take larger than this is still sent, alone)."""

Task = Callable[[str, dict[str, Any], str, str, str | None], dict[str, Any]]
"""The per-take function: path, run options as JSON, take id, run id, data folder."""


class BatchSink(Protocol):
    """What the cluster's answers go to: the batch's options and data folder, and where each
    take's outcome (or failure) is handed."""

    options_json: dict[str, Any]
    folder: str | None

    def finish(
        self, path: Path, sha: str, take_id: str, run_id: str, outcome: dict[str, Any]
    ) -> None:
        """A take's outcome (done or failed)."""

    def failed(self, path: Path, error: str) -> None:
        """A take whose task could not run."""


def _analyse_chunk(
    task: Callable[..., dict[str, Any]], items: list[tuple[Any, ...]]
) -> list[tuple[bool, Any]]:
    """Run ``task`` on each argument tuple of ``items`` (one Dask task for several takes):
    ``(True, outcome)``, or ``(False, "Name: message")`` for a take whose task raised, so that
    one take's bug fails that take only."""
    results: list[tuple[bool, Any]] = []
    for arguments in items:
        try:
            results.append((True, task(*arguments)))
        except Exception as e:  # reported per take, as a single-take task's would be
            results.append((False, f"{type(e).__name__}: {e}"))
    return results


def chunk_size(n_pending: int, in_flight: int) -> int:
    """Takes per Dask task: :data:`CHUNK_TAKES` when there are enough takes to keep every
    slot in flight busy with whole chunks, fewer for a small batch (one take per task below
    ``2 · in_flight`` takes), so that small batches still spread over every worker."""
    return max(1, min(CHUNK_TAKES, n_pending // (2 * in_flight)))


Unit = list[tuple[Path, str, str, str]]
"""The takes of one Dask task: path, hash, take id and run id of each."""


class InFlight:
    """The chunks of a batch on the cluster: those waiting to be sent, and those sent and not
    yet answered, at most ``in_flight`` of them (and :data:`SENT_BYTES_IN_FLIGHT` of takes
    when sending bytes); each sent with ``sent`` (the data folder's files the runs read) as
    bytes (:func:`analyse_sent`), else as paths (``task``)."""

    def __init__(
        self,
        engine: Engine,
        pending: list[tuple[Path, str]],
        batch: BatchSink,
        task: Task,
        sent: SentFiles | None,
    ) -> None:
        from collections import deque

        self.engine = engine
        self.client = engine.client()
        self.batch = batch
        self.task = task
        self.sent = sent
        self.in_flight = max(8, 4 * max(1, engine.n_workers()))
        size = chunk_size(len(pending), self.in_flight)
        self.units: deque[list[tuple[Path, str]]] = deque(
            pending[start : start + size] for start in range(0, len(pending), size)
        )
        self.meta: dict[str, Unit] = {}
        self.sizes: dict[str, int] = {}

    def room(self) -> bool:
        """Whether another chunk may be sent: slots left, and bytes left when sending bytes."""
        return len(self.meta) < self.in_flight and (
            not self.meta or sum(self.sizes.values()) < SENT_BYTES_IN_FLIGHT
        )

    def submit(self) -> Any:
        """Send the next chunk; its future, or None when none is left."""
        if not self.units:
            return None
        unit = [(path, sha, new_id(), new_id()) for path, sha in self.units.popleft()]
        size = 0
        options, folder, sent = self.batch.options_json, self.batch.folder, self.sent
        if sent is None:
            items: list[tuple[Any, ...]] = [
                (str(path), options, take_id, run_id, folder) for path, _, take_id, run_id in unit
            ]
        else:
            items = [
                (pack(path.parent, [path]), options, take_id, run_id, sent)
                for path, _, take_id, run_id in unit
            ]
            size = sum(item[0].size_bytes for item in items)
        _, sha, _, run_id = unit[0]
        future = self.client.submit(
            _analyse_chunk,
            self.task if sent is None else analyse_sent,
            items,
            key=f"analyse-{len(unit)}-{sha[:16]}-{run_id[:8]}",
            pure=False,
        )
        self.meta[future.key] = unit
        self.sizes[future.key] = size
        return future

    def collect(self, future: Any) -> None:
        """Finish the takes of an answered chunk (or fail them, or send them again alone)."""
        unit = self.meta.pop(future.key)
        self.sizes.pop(future.key, None)
        try:
            results = future.result()
        except Exception as e:  # a crashed worker (KilledWorker) or a lost scheduler
            self._lost(unit, e)
        else:
            for (path, sha, take_id, run_id), (ran, outcome) in zip(unit, results, strict=True):
                if ran:
                    self.batch.finish(path, sha, take_id, run_id, outcome)
                else:
                    self.batch.failed(path, f"internal error: {outcome}")
        future.release()

    def _lost(self, unit: Unit, error: Exception) -> None:
        lost = self.engine.lost_after_settling(error)
        if lost is not None:  # every task in flight is cancelled: stop, store nothing
            raise lost from error
        name = type(error).__name__
        if name == "KilledWorker" and len(unit) > 1:
            # Which take killed the workers is not known: each is sent again alone, so
            # only the one that kills two more fails (ALLOWED_FAILURES).
            self.units.extendleft([(path, sha)] for path, sha, _, _ in reversed(unit))
            return
        reason = (
            f"worker died while analysing this take ({name}: {error})"
            if name == "KilledWorker"
            else f"internal error: {name}: {error}"
        )
        for path, _, _, _ in unit:
            self.batch.failed(path, reason)


def _submit_and_collect(flight: InFlight) -> None:
    """Send the pending takes in chunks, a bounded number in flight, finishing each chunk's
    takes as it is answered."""
    from distributed import as_completed

    first: list[Any] = []
    while flight.room() and (following := flight.submit()) is not None:
        first.append(following)
    waiting = as_completed(first)  # type: ignore[no-untyped-call]
    for future in waiting:
        flight.collect(future)
        while flight.room():
            following = flight.submit()
            if following is None:
                break
            waiting.add(following)  # type: ignore[no-untyped-call]


def run_chunks(
    engine: Engine,
    pending: list[tuple[Path, str]],
    batch: BatchSink,
    task: Task,
    sent: SentFiles | None,
) -> None:
    """Analyse the pending takes (path and hash) on the cluster, handing each to ``batch``;
    with ``sent`` (the data folder's files the runs read) as bytes, else as paths.

    Raises
    ------
    ClusterError
        When the scheduler is lost (:meth:`Engine.lost_connection`, :meth:`Engine.lost`).
    """
    from distributed.comm.core import CommClosedError

    try:
        _submit_and_collect(InFlight(engine, pending, batch, task, sent))
    except CommClosedError as e:  # a call to the scheduler found it gone
        raise engine.lost_connection(e) from e
    except OSError as e:  # a timeout while the client reconnects; a full disk stays itself
        lost = engine.lost(e)
        if lost is None:
            raise
        raise lost from e
