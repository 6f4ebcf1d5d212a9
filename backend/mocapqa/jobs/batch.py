"""Batch analysis of every motion file under some paths, on Dask or in this process.

:func:`run_batch` finds the takes (:func:`discover`), hashes each (reading it in chunks, or
taking the hash recorded for the same path, size and modification time), skips those whose
content, options and mocapqa version already have a done run, sends the rest to the workers
(:func:`mocapqa.jobs.take_task.analyse_path`, a bounded number in flight) and, as each
finishes, stores its take and done run in one transaction and writes its result row.
Workers that cannot read the client's files or the data folder (another machine) are sent
each take's bytes and send the run's files back (:mod:`mocapqa.jobs.sent_files`), with at
most :data:`~mocapqa.jobs.batch_dask.SENT_BYTES_IN_FLIGHT` of takes on their way at once
(:mod:`mocapqa.jobs.batch_dask`).
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
from mocapqa.jobs.batch_dask import Task, run_chunks
from mocapqa.jobs.engine import Engine
from mocapqa.jobs.sent_files import SentFiles
from mocapqa.jobs.take_task import (
    RETURNED_FILES,
    analyse_path,
    content_sha256,
    copy_take,
    sent_models,
)
from mocapqa.store.shoots import ShootStore
from mocapqa.store.stamps import new_id
from mocapqa.store.take_writer import DoneTake

if TYPE_CHECKING:
    from mocapqa.pipeline.options import AnalysisOptions

__all__ = [
    "MOTION_SUFFIXES",
    "SIDECAR_REASON",
    "STORE_EVERY_S",
    "STORE_EVERY_TAKES",
    "BatchCounts",
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


STORE_EVERY_TAKES = 64
"""Done takes stored per transaction in a batch."""
STORE_EVERY_S = 1.0
"""Seconds after a store from which the next done take is stored at once (with any held)."""
Row = dict[str, Any]
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
    counts = BatchCounts()
    if options.limits_model is None:  # the shoot's model, as for the server's runs
        chosen = shoots.run_limits_model(None, shoot_id)
        options = dataclasses.replace(options, limits_model=chosen)
    options_json = options.to_json()
    batch = _Batch(shoots, options_json, data_dir, shoot_id, counts, on_row)
    pending = batch.pending(list(discover(paths)), on_total)
    try:
        if engine is None:
            batch.run_here(pending, task)
        elif pending:  # a finished batch never starts (or connects to) a cluster
            batch.run_on_dask(engine, pending, task, send, options.limits_model)
    finally:  # takes finished before an interruption are stored, with their rows
        batch.stores.flush()
    return counts


class _Batch:
    """One batch's steps: which takes are left to analyse, where they run, and what is
    stored and emitted for each (``on_row`` receives each row once counted)."""

    def __init__(
        self,
        shoots: ShootStore,
        options_json: dict[str, Any],
        data_dir: Path | None,
        shoot_id: str | None,
        counts: BatchCounts,
        on_row: Callable[[Row], None],
    ) -> None:
        self.shoots = shoots
        self.options_json = options_json
        self.data_dir = data_dir
        self.folder = str(data_dir) if data_dir is not None else None
        self.shoot_id = shoot_id
        self.counts = counts
        self.on_row = on_row
        self.stores = _StoreInBatches(shoots, self.emit)

    def emit(self, row: Row) -> None:
        """Count a result row and pass it on."""
        self.counts.add(row)
        self.on_row(row)

    def failed(self, path: Path, error: str) -> None:
        """Emit the row of a take that failed."""
        self.emit({"source": str(path), "status": "failed", "error": error})

    def pending(
        self, items: list[tuple[Path, str | None]], on_total: Callable[[int], None] | None
    ) -> list[tuple[Path, str]]:
        """The takes to analyse, with their hashes; the others are emitted as skipped."""
        self.counts.total = len(items)
        if on_total is not None:
            on_total(len(items))
        return self._unfinished(self._distinct(items))

    def _distinct(self, items: list[tuple[Path, str | None]]) -> list[tuple[Path, str]]:
        """The takes of ``items`` with their hashes, the first of each content only (files
        skipped by name and later copies are emitted as skipped)."""
        todo: list[tuple[Path, str]] = []
        seen: dict[str, Path] = {}
        takes = [path for path, reason in items if reason is None]
        known = self.shoots.known_hashes([str(p.resolve()) for p in takes])
        learned: list[dict[str, Any]] = []
        for path, reason in items:
            if reason is not None:
                self.emit({"source": str(path), "status": "skipped", "error": reason})
                continue
            sha = _content_hash(path, known, learned)
            if sha in seen:
                same = f"same content as {seen[sha]}"
                self.emit({"source": str(path), "status": "skipped", "error": same})
                continue
            seen[sha] = path
            todo.append((path, sha))
        self.shoots.remember_hashes(learned)
        return todo

    def _unfinished(self, todo: list[tuple[Path, str]]) -> list[tuple[Path, str]]:
        """The takes of ``todo`` without a done run of these options and this version (the
        others are emitted as skipped, with their stored QA columns)."""
        finished = self.shoots.finished([sha for _, sha in todo], self.options_json)
        stored = self.shoots.qa_rows(list(finished.values()))
        pending: list[tuple[Path, str]] = []
        for path, sha in todo:
            take_id = finished.get(sha)
            if take_id is None:
                pending.append((path, sha))
                continue
            self.emit(
                {
                    **_summary_row(stored.get(take_id, {})),
                    "source": str(path),
                    "status": "skipped",
                    "error": "already analysed with these options and this version",
                    "take_id": take_id,
                }
            )
        return pending

    def finish(self, path: Path, sha: str, take_id: str, run_id: str, outcome: Row) -> None:
        """Hold a done take to be stored (its row emitted once stored), or emit a failure."""
        if outcome["status"] != "done":
            self.failed(path, outcome["error"])
            return
        values = {**outcome["take"], "sha256": sha, "shoot_id": self.shoot_id}
        if RETURNED_FILES in outcome and self.data_dir is not None:
            returned = outcome[RETURNED_FILES]
            _store_returned(self.data_dir, returned, path, (take_id, run_id), values)
        summary = outcome["summary"]
        done = DoneTake(values, run_id, self.options_json, summary, float(outcome["time_s"]))
        row = {
            **_summary_row(summary["qa"]),
            "source": str(path),
            "status": "done",
            "error": None,
            "take_id": take_id,
            "review_status": "unreviewed",
        }
        self.stores.add(done, row)

    def run_here(self, pending: list[tuple[Path, str]], task: Task) -> None:
        """Analyse the takes one after another in this process."""
        for path, sha in pending:
            take_id, run_id = new_id(), new_id()
            outcome = task(str(path), self.options_json, take_id, run_id, self.folder)
            self.finish(path, sha, take_id, run_id, outcome)

    def run_on_dask(
        self,
        engine: Engine,
        pending: list[tuple[Path, str]],
        task: Task,
        send: Send,
        model: str | None,
    ) -> None:
        """Analyse the takes on the cluster: as paths, or as bytes (with the registered
        limits ``model``'s file) to workers that do not share the client's files."""
        sent = None
        sample = _sample_file(pending[0][0])
        if send == "bytes" or (send == "auto" and not engine.shares_disk(sample, self.data_dir)):
            sent = sent_models(self.data_dir, model)
        run_chunks(engine, pending, self, task, sent)


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
    data_dir: Path,
    files: SentFiles,
    source: Path,
    ids: tuple[str, str],
    values: dict[str, Any],
) -> None:
    """Write what a worker that shares nothing sent back (the run's files, the take's reading
    record: ``ids`` are the take's and the run's) into the data folder, and copy the take
    there from the client's own disk."""
    from mocapqa.store.files import FileStore

    take_id, run_id = ids
    store = FileStore(data_dir)
    allowed = (store.run_dir(run_id), store.take_dir(take_id))
    for target, data in files.targets(store.root):
        if not any(target.is_relative_to(folder) for folder in allowed):
            raise InputError(f"Expected a worker to return its run's files only, got {target}")
        store.write_bytes(target, data)
    copy_take(source, store.take_dir(take_id) / str(values["file_name"]))
