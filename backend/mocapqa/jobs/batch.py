"""Batch analysis of every motion file under some paths, on Dask or in this process.

:func:`run_batch` finds the takes (:func:`discover`), hashes each (reading it in chunks, or
taking the hash recorded for the same path, size and modification time), skips those whose
content, options and mocapqa version already have a done run, sends the rest to the workers
(:func:`mocapqa.jobs.take_task.analyse_path`, a bounded number in flight) and, as each
finishes, stores its take and done run in one transaction and writes its result row.
Workers that cannot read the client's files or the data folder (another machine) are sent
each take's bytes and send the run's files back (:mod:`mocapqa.jobs.sent_files`), with at
most :data:`SENT_BYTES_IN_FLIGHT` of takes on their way at once.
Nothing is stored for a take until its run is complete, so an interrupted batch (Ctrl-C, a
lost scheduler) leaves no half-made rows, and running it again finishes the rest without
duplicates (an interrupted task may leave an orphan output folder behind, never a row).
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path, PurePath
from typing import TYPE_CHECKING, Any, Literal

from mocapqa.errors import InputError, MocapQAError
from mocapqa.io.keypoint_csv import is_csv_sidecar
from mocapqa.jobs.engine import Engine
from mocapqa.jobs.sent_files import SentFiles, pack
from mocapqa.jobs.take_task import (
    RETURNED_FILES,
    analyse_path,
    analyse_sent,
    content_sha256,
    sent_models,
)
from mocapqa.store.repository import new_id
from mocapqa.store.shoots import DoneTake, ShootStore

if TYPE_CHECKING:
    from mocapqa.pipeline.options import AnalysisOptions

__all__ = [
    "CHUNK_TAKES",
    "MOTION_SUFFIXES",
    "SENT_BYTES_IN_FLIGHT",
    "SIDECAR_REASON",
    "STORE_EVERY_S",
    "STORE_EVERY_TAKES",
    "BatchCounts",
    "chunk_size",
    "discover",
    "run_batch",
    "skip_reason",
]

MOTION_SUFFIXES = (".bvh", ".trc", ".c3d", ".csv", ".json", ".npy", ".npz", ".pbtxt")
"""File suffixes a batch analyses; other files under a folder are ignored."""
SIDECAR_REASON = "a keypoint CSV's .meta.json sidecar (read with its CSV), not a take"
"""Why a batch skips a CSV's sidecar (a shoot import gives its own reason: it does not read it)."""


def skip_reason(name: str | Path) -> str | None:
    """Why a file (by name) is not a take, or None when it is one: a suffix not in
    :data:`MOTION_SUFFIXES`, or a keypoint CSV's ``.meta.json`` sidecar. Batches and shoot
    imports share this rule."""
    if is_csv_sidecar(name):
        return SIDECAR_REASON
    if PurePath(name).suffix.lower() not in MOTION_SUFFIXES:
        return "not a motion file"
    return None


CHUNK_TAKES = 4
"""Takes per Dask task in a large batch. A task costs the client, scheduler and worker about
9 ms of CPU beyond the take's own work (about 95 ms): one take per task made the Dask path
about 10 % dearer than a loop, four per task make it about 2 % (docs/batch.md)."""

STORE_EVERY_TAKES = 64
"""Done takes stored per transaction in a batch."""
STORE_EVERY_S = 1.0
"""Seconds after a store from which the next done take is stored at once (with any held)."""
SENT_BYTES_IN_FLIGHT = 256 * 1024 * 1024
"""Most bytes of takes sent to workers and not yet answered, when the workers do not share
the client's files (one take larger than this is still sent, alone)."""

Row = dict[str, Any]
Task = Callable[[str, dict[str, Any], str, str, str | None], dict[str, Any]]
Send = Literal["auto", "paths", "bytes"]


@dataclass
class BatchCounts:
    """Tallies of a batch, updated as rows come in."""

    total: int = 0
    done: int = 0
    failed: int = 0
    skipped: int = 0
    frames: int = 0
    started: float = field(default_factory=time.perf_counter)

    def add(self, row: Row) -> None:
        """Count one result row."""
        status = str(row["status"])
        setattr(self, status, getattr(self, status) + 1)
        if status == "done":
            self.frames += int(row.get("n_frames") or 0)


def _is_frame_folder(folder: Path, names: list[str]) -> bool:
    if sum(n.lower().endswith(".json") for n in names) < 2:
        return False
    from mocapqa.pipeline.loading import detect_take_format

    try:
        return detect_take_format(folder) == "openpose"
    except MocapQAError:
        return False


def discover(paths: Iterable[Path]) -> Iterator[tuple[Path, str | None]]:
    """Every take under ``paths``, in a stable order, with a reason when it is skipped.

    A file named on the command line is a take when :func:`skip_reason` finds none (else it
    is skipped, with the reason); under a folder, such files are takes and other files
    (a keypoint CSV's ``.meta.json`` sidecar among them) are ignored. A folder of OpenPose
    JSON frames is one take.

    Raises
    ------
    InputError
        When a path does not exist.
    """
    for path in paths:
        if not path.exists():
            raise InputError(f"Expected an existing file or folder, got nothing at {path}")
        if path.is_file():
            yield path, skip_reason(path)
            continue
        for folder, dirs, names in os.walk(path):
            dirs.sort()
            here = Path(folder)
            if _is_frame_folder(here, names):
                yield here, None
                names = [n for n in names if not n.endswith(".json")]
            for name in sorted(names):
                if skip_reason(name) is None:
                    yield here / name, None


def _content_hash(
    path: Path, known: dict[str, tuple[int, int, str]], learned: list[dict[str, Any]]
) -> str:
    """The take's SHA-256, from the cache when its size and modification time are unchanged."""
    key = str(path.resolve())
    if path.is_file():
        stat = path.stat()
        cached = known.get(key)
        if cached is not None and cached[:2] == (stat.st_size, stat.st_mtime_ns):
            return cached[2]
        sha = content_sha256(path)
        learned.append(
            {"path": key, "size_bytes": stat.st_size, "mtime_ns": stat.st_mtime_ns, "sha256": sha}
        )
        return sha
    return content_sha256(path)  # frame folders: hashed each time (they are few)


def _summary_row(qa: dict[str, Any]) -> Row:
    return {key: value for key, value in qa.items() if key != "joint_violations"}


def run_batch(
    paths: Iterable[Path],
    shoots: ShootStore,
    options: AnalysisOptions,
    on_row: Callable[[Row], None],
    engine: Engine | None = None,
    data_dir: Path | None = None,
    shoot_id: str | None = None,
    on_total: Callable[[int], None] | None = None,
    task: Task = analyse_path,
    send: Send = "auto",
) -> BatchCounts:
    """Analyse every take under ``paths``; ``on_row`` receives one result row per take.

    Parameters
    ----------
    paths : iterable of Path
        Files and folders.
    shoots : ShootStore
        Where takes and runs are stored (the dashboard's database).
    options : AnalysisOptions
        Options of every run.
    on_row : callable
        Called with each result row (``source``, ``status``, ``error``, ``take_id`` and the
        QA summary columns) as soon as it is known.
    engine : Engine, optional
        Where tasks run; None runs them one after another in this process.
    data_dir : Path, optional
        The data folder the workers write run outputs and take copies to; None stores rows
        only.
    shoot_id : str, optional
        Shoot of the new takes.
    on_total : callable, optional
        Called once with the number of rows to come.
    task : callable
        The per-take function (the default analyses and stores; tests pass wrappers).
    send : {"auto", "paths", "bytes"}
        What a Dask worker is sent: the take's path (it reads the client's files and writes
        the data folder), its bytes (:func:`mocapqa.jobs.take_task.analyse_sent`; the run's
        files come back), or "auto": paths when every worker shares the client's files
        (:meth:`Engine.shares_disk`), else bytes.

    Returns
    -------
    BatchCounts

    Raises
    ------
    ClusterError
        When the Dask scheduler cannot be reached or is lost mid-batch; the takes finished
        before are stored and have their rows, the others have neither.
    """
    from mocapqa.limits.catalog import DEFAULT_MODEL

    counts = BatchCounts()
    if options.limits_model is None:  # the shoot's model, as for the server's runs
        chosen = shoots.limits_model(shoot_id) if shoot_id else DEFAULT_MODEL
        options = dataclasses.replace(options, limits_model=chosen)
    options_json = options.to_json()
    items = list(discover(paths))
    counts.total = len(items)
    if on_total is not None:
        on_total(len(items))

    def emit(row: Row) -> None:
        counts.add(row)
        on_row(row)

    todo: list[tuple[Path, str]] = []
    seen: dict[str, Path] = {}
    takes = [path for path, reason in items if reason is None]
    known = shoots.known_hashes([str(p.resolve()) for p in takes])
    learned: list[dict[str, Any]] = []
    for path, reason in items:
        if reason is not None:
            emit({"source": str(path), "status": "skipped", "error": reason})
            continue
        sha = _content_hash(path, known, learned)
        if sha in seen:
            emit(
                {"source": str(path), "status": "skipped", "error": f"same content as {seen[sha]}"}
            )
            continue
        seen[sha] = path
        todo.append((path, sha))
    shoots.remember_hashes(learned)

    finished = shoots.finished([sha for _, sha in todo], options_json)
    stored = shoots.qa_rows(list(finished.values()))
    pending: list[tuple[Path, str]] = []
    for path, sha in todo:
        take_id = finished.get(sha)
        if take_id is None:
            pending.append((path, sha))
            continue
        emit(
            {
                **_summary_row(stored.get(take_id, {})),
                "source": str(path),
                "status": "skipped",
                "error": "already analysed with these options and this version",
                "take_id": take_id,
            }
        )

    folder = str(data_dir) if data_dir is not None else None

    def finish(path: Path, sha: str, take_id: str, run_id: str, outcome: dict[str, Any]) -> None:
        if outcome["status"] != "done":
            emit({"source": str(path), "status": "failed", "error": outcome["error"]})
            return
        values = {**outcome["take"], "sha256": sha, "shoot_id": shoot_id}
        if RETURNED_FILES in outcome and data_dir is not None:
            _store_returned(data_dir, outcome[RETURNED_FILES], path, take_id, values)
        summary = outcome["summary"]
        done = DoneTake(values, run_id, options_json, summary, float(outcome["time_s"]))
        row = {
            **_summary_row(summary["qa"]),
            "source": str(path),
            "status": "done",
            "error": None,
            "take_id": take_id,
            "review_status": "unreviewed",
        }
        stores.add(done, row)

    stores = _StoreInBatches(shoots, emit)
    try:
        if engine is None:
            for path, sha in pending:
                take_id, run_id = new_id(), new_id()
                outcome = task(str(path), options_json, take_id, run_id, folder)
                finish(path, sha, take_id, run_id, outcome)
        elif pending:  # a finished batch never starts (or connects to) a cluster
            sent = None
            sample = _sample_file(pending[0][0])
            if send == "bytes" or (send == "auto" and not engine.shares_disk(sample, data_dir)):
                sent = sent_models(data_dir, options.limits_model)
            _run_on_dask(engine, pending, options_json, folder, task, sent, finish, emit)
    finally:  # takes finished before an interruption are stored, with their rows
        stores.flush()
    return counts


class _StoreInBatches:
    """Done takes stored in one transaction when :data:`STORE_EVERY_TAKES` of them are held or
    :data:`STORE_EVERY_S` seconds have passed since the last store (so a batch's first take is
    stored as soon as it is done, and a slow batch stores each take as it comes), then their
    rows emitted: one commit per take cost the client more than the rest of its work
    (docs/batch.md)."""

    def __init__(self, shoots: ShootStore, emit: Callable[[Row], None]) -> None:
        self.shoots = shoots
        self.emit = emit
        self.held: list[tuple[DoneTake, Row]] = []
        self.stored_at = time.monotonic() - STORE_EVERY_S

    def add(self, done: DoneTake, row: Row) -> None:
        """Hold one done take; store the held ones when enough are held or time has passed."""
        self.held.append((done, row))
        if (
            len(self.held) >= STORE_EVERY_TAKES
            or time.monotonic() - self.stored_at >= STORE_EVERY_S
        ):
            self.flush()

    def flush(self) -> None:
        """Store every held take, then emit their rows (a row says "done" once stored)."""
        held, self.held = self.held, []
        self.stored_at = time.monotonic()
        self.shoots.record_done([done for done, _ in held])
        for _, row in held:
            self.emit(row)


def _sample_file(path: Path) -> Path:
    """A file of a take (a frame folder's first file), for asking workers whether they see it."""
    if path.is_dir():
        return next(p for p in sorted(path.iterdir()) if p.is_file())
    return path


def _store_returned(
    data_dir: Path, files: SentFiles, source: Path, take_id: str, values: dict[str, Any]
) -> None:
    """Write what a worker that shares nothing sent back (the run's files, the take's reading
    facts) into the data folder, and copy the take there from the client's own disk."""
    import shutil

    from mocapqa.store.files import FileStore

    store = FileStore(data_dir)
    allowed = (store.root / "runs", store.take_dir(take_id))
    for target, data in files.targets(store.root):
        if not any(target.is_relative_to(folder) for folder in allowed):
            raise InputError(f"Expected a worker to return its run's files only, got {target}")
        store.write_bytes(target, data)
    copy = store.take_dir(take_id) / str(values["file_name"])
    if source.is_dir():
        shutil.copytree(source, copy, dirs_exist_ok=True)
    else:
        shutil.copyfile(source, copy)


def _run_on_dask(
    engine: Engine,
    pending: list[tuple[Path, str]],
    options_json: dict[str, Any],
    folder: str | None,
    task: Task,
    sent: SentFiles | None,
    finish: Callable[[Path, str, str, str, dict[str, Any]], None],
    emit: Callable[[Row], None],
) -> None:
    from distributed.comm.core import CommClosedError

    try:
        _submit_and_collect(engine, pending, options_json, folder, task, sent, finish, emit)
    except CommClosedError as e:  # a call to the scheduler found it gone
        raise engine.lost_connection(e) from e
    except OSError as e:  # a timeout while the client reconnects; a full disk stays itself
        lost = engine.lost(e)
        if lost is None:
            raise
        raise lost from e


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


def _submit_and_collect(
    engine: Engine,
    pending: list[tuple[Path, str]],
    options_json: dict[str, Any],
    folder: str | None,
    task: Task,
    sent: SentFiles | None,
    finish: Callable[[Path, str, str, str, dict[str, Any]], None],
    emit: Callable[[Row], None],
) -> None:
    """Send the pending takes in chunks, a bounded number in flight; with ``sent`` (the data
    folder's files the runs read) as bytes (:func:`analyse_sent`), else as paths (``task``)."""
    from collections import deque

    from distributed import as_completed

    client = engine.client()
    in_flight = max(8, 4 * max(1, engine.n_workers()))
    size = chunk_size(len(pending), in_flight)
    units: deque[list[tuple[Path, str]]] = deque(
        pending[start : start + size] for start in range(0, len(pending), size)
    )
    meta: dict[str, list[tuple[Path, str, str, str]]] = {}
    sizes: dict[str, int] = {}

    def submit() -> Any:
        if not units:
            return None
        unit = [(path, sha, new_id(), new_id()) for path, sha in units.popleft()]
        size = 0
        if sent is None:
            items: list[tuple[Any, ...]] = [
                (str(path), options_json, take_id, run_id, folder)
                for path, _, take_id, run_id in unit
            ]
        else:
            items = [
                (pack(path.parent, [path]), options_json, take_id, run_id, sent)
                for path, _, take_id, run_id in unit
            ]
            size = sum(item[0].size_bytes for item in items)
        _, sha, _, run_id = unit[0]
        future = client.submit(
            _analyse_chunk,
            task if sent is None else analyse_sent,
            items,
            key=f"analyse-{len(unit)}-{sha[:16]}-{run_id[:8]}",
            pure=False,
        )
        meta[future.key] = unit
        sizes[future.key] = size
        return future

    def room() -> bool:
        """Whether another chunk may be sent: slots left, and bytes left when sending bytes."""
        return len(meta) < in_flight and (not meta or sum(sizes.values()) < SENT_BYTES_IN_FLIGHT)

    first: list[Any] = []
    while room() and (following := submit()) is not None:
        first.append(following)
    waiting = as_completed(first)  # type: ignore[no-untyped-call]
    for future in waiting:
        unit = meta.pop(future.key)
        sizes.pop(future.key, None)
        try:
            results = future.result()
        except Exception as e:  # a crashed worker (KilledWorker) or a lost scheduler
            lost = engine.lost_after_settling(e)
            if lost is not None:  # every task in flight is cancelled: stop, store nothing
                raise lost from e
            name = type(e).__name__
            if name == "KilledWorker" and len(unit) > 1:
                # Which take killed the workers is not known: each is sent again alone, so
                # only the one that kills two more fails (ALLOWED_FAILURES).
                units.extendleft([(path, sha)] for path, sha, _, _ in reversed(unit))
            else:
                reason = (
                    f"worker died while analysing this take ({name}: {e})"
                    if name == "KilledWorker"
                    else f"internal error: {name}: {e}"
                )
                for path, _, _, _ in unit:
                    emit({"source": str(path), "status": "failed", "error": reason})
        else:
            for (path, sha, take_id, run_id), (ran, outcome) in zip(unit, results, strict=True):
                if ran:
                    finish(path, sha, take_id, run_id, outcome)
                else:
                    error = f"internal error: {outcome}"
                    emit({"source": str(path), "status": "failed", "error": error})
        future.release()
        while room():
            following = submit()
            if following is None:
                break
            waiting.add(following)  # type: ignore[no-untyped-call]
