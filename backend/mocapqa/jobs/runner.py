"""Background analysis runs: a thread pool outside the request, with progress in the database.

A run's outputs are written to its folder (each file atomically) *before* the run is marked
done, so a run seen as done always has complete files; a server that stops mid-run leaves the
run queued or running, and :meth:`JobRunner.start` re-queues it on the next start (counting
its attempts: a run that was started ``max_attempts`` times and never finished is failed with
the reason instead, so a take that crashes the server cannot do so forever). Deleting a take
cancels its runs (:meth:`JobRunner.cancel`) and removes their folders. numpy and the
file I/O release the GIL for most of the work, so the event loop stays responsive.

A twist run of a take in a shoot uses the reviewer prior of the shoot's other takes'
decisions (:func:`mocapqa.jobs.shoot_prior.shoot_prior`), built when the run starts and
recorded in its folder and report; an approved take gets none. A prior only ever shapes the
run being made: nothing here re-runs a take because its shoot's decisions changed.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from mocapqa.errors import InputError, MocapQAError
from mocapqa.io.guards import ReadLimits
from mocapqa.jobs.engine import Engine
from mocapqa.jobs.fair_queue import FairQueue
from mocapqa.jobs.reading_record import read_options_of
from mocapqa.jobs.rendered import render_thumbnail
from mocapqa.jobs.run_folder import RunFolder
from mocapqa.jobs.run_outputs import run_summary, write_outputs
from mocapqa.jobs.sent_files import SentFiles
from mocapqa.jobs.shoot_prior import shoot_prior
from mocapqa.jobs.stored_run import load_points, load_report
from mocapqa.limits.catalog import ModelCatalog
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.loading import ReadOptions, Take, read_take_file
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.render.service import RenderService
from mocapqa.store.decisions import IntervalDecisions
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository
from mocapqa.twist.reviewer_prior import ReviewerPrior

__all__ = ["JobRunner"]

log = logging.getLogger(__name__)


class _RunCancelledError(Exception):
    """Raised inside a run whose take was deleted, at its next progress report."""


class JobRunner:
    """Runs analyses on worker threads, taking clients in turn (:class:`FairQueue`).

    Parameters
    ----------
    repository : Repository
        Where runs are recorded.
    files : FileStore
        Where takes and outputs live.
    workers : int
        Worker threads.
    renderer : RenderService, optional
        The app's render thread; with it each run gets a rendered ``thumbnail.png`` after the
        analysis (skipped, with the SVG thumbnail as fallback, when rendering is unavailable).
    max_attempts : int
        Starts of a run interrupted by a server stop before :meth:`start` fails it.
    read_limits : ReadLimits, optional
        Limits for re-reading a stored take (the upload was checked against the same).
    engine : Engine, optional
        A Dask engine: the analysis then runs on the cluster while the thread here waits,
        records progress and renders the thumbnail (workers that cannot read the data folder
        are sent the take's bytes and return the run's files: :mod:`mocapqa.jobs.sent_files`).
        Without one, the analysis runs on this thread (faster for one take, see
        ``docs/batch.md``).
    max_in_line : int, optional
        Most runs of one client in the workers' line (waiting or running): more are held,
        as ids, and line up as the client's runs finish (:class:`FairQueue`'s
        ``per_client``; the server passes ``max_queued_runs_per_user``). None: no limit.
    """

    def __init__(
        self,
        repository: Repository,
        files: FileStore,
        workers: int = 2,
        renderer: RenderService | None = None,
        max_attempts: int = 2,
        read_limits: ReadLimits | None = None,
        engine: Engine | None = None,
        max_in_line: int | None = None,
    ) -> None:
        self.engine = engine
        self.repository = repository
        self.files = files
        self.renderer = renderer
        self.max_attempts = max(1, max_attempts)
        self.read_limits = read_limits
        self._workers = max(1, workers)
        self._threads: list[threading.Thread] = []
        self._queue = FairQueue(max_in_line)
        self._futures: dict[str, Future[None]] = {}
        self._clients: dict[str, str] = {}
        self._cancelled: set[str] = set()
        self._preloaded: dict[str, Take] = {}
        self._lock = threading.Lock()
        self._held: dict[str, int] = {}
        self._shares_disk: bool | None = None

    def start(self) -> list[str]:
        """Start the workers; re-queue runs left by a stopped server (failing those already
        started ``max_attempts`` times, with the reason); returns the re-queued ids."""
        ids = self.repository.recover_interrupted(self.max_attempts)
        for run_id in ids:
            self.submit(run_id, client="restart")
        for number in range(self._workers):
            thread = threading.Thread(target=self._work, name=f"run-{number}", daemon=True)
            thread.start()
            self._threads.append(thread)
        return ids

    def submit(self, run_id: str, take: Take | None = None, client: str = "local") -> None:
        """Queue a run (already recorded as queued) for a worker, in ``client``'s line.

        ``take`` is the take as already read by the upload, which spares the worker a second
        parse of the same bytes; a run held back (``client`` has ``max_in_line`` runs in
        line) does not keep it, so a large import holds ids, not parsed takes.
        """
        with self._lock:
            if take is not None:
                self._preloaded[run_id] = take
            self._futures[run_id] = Future()
            self._clients[run_id] = client
        if not self._queue.put(client, run_id):
            with self._lock:
                self._preloaded.pop(run_id, None)

    def pending(self, client: str) -> int:
        """Runs of ``client`` queued (held back included) or running, and places held for
        runs about to be submitted (:meth:`places`)."""
        with self._lock:
            return self._pending(client)

    def _pending(self, client: str) -> int:
        held = self._held.get(client, 0)
        return held + sum(1 for c in self._clients.values() if c == client)

    @contextmanager
    def places(self, client: str, wanted: int, limit: int) -> Iterator[int]:
        """Hold up to ``wanted`` of ``client``'s free places under ``limit`` pending runs
        while the block records and submits its runs; yields how many it got (0: none free).

        Checking the count and submitting later let parallel requests all pass the check
        (36 at once got 25 places of 20); places are taken under the runner's lock instead,
        and given back when the block ends, when its submitted runs count in their stead.
        """
        with self._lock:
            granted = max(0, min(wanted, limit - self._pending(client)))
            self._held[client] = self._held.get(client, 0) + granted
        try:
            yield granted
        finally:
            with self._lock:
                left = self._held[client] - granted
                if left:
                    self._held[client] = left
                else:
                    del self._held[client]

    def in_line(self, client: str) -> int:
        """Runs of ``client`` in the workers' line: waiting for a worker or running (at most
        ``max_in_line``; :meth:`pending` also counts the runs held back)."""
        return self._queue.in_line(client)

    def cancel(self, run_ids: list[str]) -> None:
        """Stop these runs (their take is being deleted): queued ones never start, running
        ones stop at their next progress report; their output folders are removed."""
        for run_id in run_ids:
            if self._queue.remove(run_id):
                self._settle(run_id)
            else:
                with self._lock:
                    if run_id in self._clients:
                        self._cancelled.add(run_id)
            self.files.remove_run(run_id)

    def wait(self, run_id: str, timeout_s: float = 60.0) -> None:
        """Block until a submitted run has finished (for tests and the demo loader)."""
        with self._lock:
            future = self._futures.get(run_id)
        if future is not None:
            future.result(timeout=timeout_s)

    def shutdown(self) -> None:
        """Stop taking runs; running ones finish, queued ones stay queued for the next start."""
        self._queue.close()
        for thread in self._threads:
            thread.join()

    def _settle(self, run_id: str) -> None:
        self._queue.done(run_id)  # the client's next held run lines up
        with self._lock:
            future = self._futures.pop(run_id, None)
            self._clients.pop(run_id, None)
            self._preloaded.pop(run_id, None)
            cancelled = run_id in self._cancelled
            self._cancelled.discard(run_id)
        if cancelled:
            self.files.remove_run(run_id)
        if future is not None:
            future.set_result(None)

    def _work(self) -> None:
        while (run_id := self._queue.get()) is not None:
            try:
                self._execute(run_id)
            finally:
                self._settle(run_id)

    def _execute(self, run_id: str) -> None:
        started = time.perf_counter()
        try:
            self.repository.mark_running(run_id)
            run = self.repository.get_run(run_id)
            take = self.repository.get_take(str(run["take_id"]))
            path = self.files.take_dir(str(take["id"])) / str(take["file_name"])
            options = AnalysisOptions.from_json(run["options"])
            with self._lock:
                preloaded = self._preloaded.pop(run_id, None)
            reading = read_options_of(path.parent)
            prior = self._prior(take, options)
            if self.engine is not None:
                summary = self._execute_on_dask(
                    self.engine, run_id, run, take, path, reading, prior
                )
            else:
                read = preloaded or read_take_file(
                    path, str(take["format"]), str(take["name"]), reading, self.read_limits
                )
                summary = self._execute_here(run_id, read, options, path, prior)
            self.repository.finish_run(run_id, summary, None, time.perf_counter() - started)
        except _RunCancelledError:
            log.info("run %s cancelled: its take was deleted", run_id)
        except Exception as e:
            if self._was_cancelled(run_id):
                # Its take and folder were deleted under it (between two progress reports):
                # whatever that broke, the run is cancelled, not failed.
                log.info("run %s cancelled: its take was deleted (%s)", run_id, type(e).__name__)
            elif isinstance(e, MocapQAError):
                self._fail(run_id, str(e), started)
            else:  # a bug must not leave the run "running" forever
                log.exception("run %s failed", run_id)
                self._fail(run_id, f"internal error: {type(e).__name__}: {e}", started)

    def _was_cancelled(self, run_id: str) -> bool:
        """Whether the run's take was deleted while it ran."""
        with self._lock:
            return run_id in self._cancelled

    def _prior(self, take: dict[str, Any], options: AnalysisOptions) -> ReviewerPrior | None:
        """The reviewer prior of a new robust twist run of ``take`` (None for other runs, a
        take outside a shoot or approved, or a shoot without decisions on its other takes)."""
        twist = "twist" in options.checks and options.twist_method == "robust"
        if take.get("kind") != "motion" or not twist:
            return None
        return shoot_prior(IntervalDecisions(self.repository.engine), self.files, take)

    def _progress(self, run_id: str) -> Callable[[int, str], None]:
        """A run's progress report: recorded at most every 0.2 s (and from 95 %), and where
        the run's take was deleted, :class:`_RunCancelledError`."""
        last = [0.0]

        def progress(percent: int, step: str) -> None:
            with self._lock:
                if run_id in self._cancelled:
                    raise _RunCancelledError(run_id)
            now = time.perf_counter()
            if now - last[0] > 0.2 or percent >= 95:
                last[0] = now
                self.repository.set_progress(run_id, percent, step)

        return progress

    def _execute_here(
        self,
        run_id: str,
        take: Take,
        options: AnalysisOptions,
        path: Path,
        prior: ReviewerPrior | None = None,
    ) -> dict[str, Any]:
        """Analyse on this thread (with the reviewer ``prior``), write the run's files and
        thumbnail; returns the summary."""
        progress = self._progress(run_id)
        catalog = ModelCatalog.of_data_folder(self.files.root)
        result = analyze(take, options, progress, catalog, prior)
        progress(96, "writing the outputs")
        write_outputs(self.files, run_id, result, path, prior)
        if self.renderer is not None:
            progress(97, "rendering the thumbnail")
            render_thumbnail(self.files, run_id, result.report, result.raw_points, self.renderer)
        return run_summary(result)

    def _execute_on_dask(
        self,
        engine: Engine,
        run_id: str,
        run: dict[str, Any],
        take: dict[str, Any],
        path: Path,
        reading: ReadOptions,
        prior: ReviewerPrior | None = None,
    ) -> dict[str, Any]:
        """Analyse on the cluster (the take's path, or its bytes to workers that do not share
        the data folder), with the read options and reviewer ``prior`` read here; returns the
        summary."""
        from mocapqa.jobs.sent_files import pack
        from mocapqa.jobs.take_task import analyse_stored, analyse_stored_sent, sent_models

        self.repository.set_progress(run_id, 10, "analysing on the Dask cluster")
        if self._shares_disk is None:  # asked once: the cluster's workers keep their disks
            self._shares_disk = engine.shares_disk(path, self.files.root)
        format_name, name, read = str(take["format"]), str(take["name"]), reading.to_json()
        recorded = None if prior is None else prior.to_json()
        if self._shares_disk:
            future = engine.client().submit(
                analyse_stored, str(path), format_name, name, run["options"], run_id,
                str(self.files.root), read, recorded, key=f"run-{run_id}", pure=False,
            )  # fmt: skip
        else:
            models = sent_models(self.files.root, run["options"].get("limits_model"))
            future = engine.client().submit(
                analyse_stored_sent, pack(path.parent, [path]), path.name, format_name, name,
                run["options"], run_id, models, read, recorded, key=f"run-{run_id}", pure=False,
            )  # fmt: skip
        try:
            answer = future.result()
        except Exception as e:  # a lost scheduler fails the run with its address
            lost = engine.lost(e)
            if lost is not None:
                raise lost from e
            raise
        written: dict[Path, bytes] = {}
        if self._shares_disk:
            summary: dict[str, Any] = answer
        else:
            summary, returned = answer
            written = self._write_returned(run_id, returned)
        if self.renderer is not None:
            self.repository.set_progress(run_id, 97, "rendering the thumbnail")
            self._render_written(run_id, written)
        return summary

    def _write_returned(self, run_id: str, returned: SentFiles) -> dict[Path, bytes]:
        """Write the run's files a worker sent back; returns them by path."""
        folder = self.files.run_dir(run_id)
        written = {}
        for target, data in returned.targets(self.files.root):
            if not target.is_relative_to(folder):
                raise InputError(f"Expected a worker to return its run's files, got {target}")
            self.files.write_bytes(target, data)
            written[target] = data
        return written

    def _render_written(self, run_id: str, written: dict[Path, bytes]) -> None:
        """The thumbnail of a run analysed on the cluster, from the report and points the
        worker sent back (``written``), else from the files it wrote in the data folder."""
        if self.renderer is None:
            return
        run = RunFolder.of(self.files, run_id)
        report = load_report(written.get(run.report, run.report))
        raw = load_points(written.get(run.points, run.points), ("raw",))["raw"]
        render_thumbnail(self.files, run_id, report, raw, self.renderer)

    def _fail(self, run_id: str, message: str, started: float) -> None:
        try:
            self.repository.finish_run(run_id, None, message, time.perf_counter() - started)
        except Exception:
            log.exception("could not record the failure of run %s", run_id)
