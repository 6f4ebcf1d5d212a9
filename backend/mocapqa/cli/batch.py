"""``mocapqa batch PATH…``: analyse every motion file under the paths, on Dask.

The command line is a fixed contract (scripts drive it)::

    mocapqa batch PATH… [--shoot NAME] [--scheduler ADDR] [--workers N] [--options JSON]
                        [--output results.parquet|csv|jsonl]

Runs are stored in the dashboard's database (``MOCAPQA_DATA_DIR`` / ``MOCAPQA_DATABASE_URL``)
and its data folder; running the same command again skips what is already done.
"""

from __future__ import annotations

import json
import logging
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from mocapqa.cli.app import app

if TYPE_CHECKING:
    from rich.console import Console
    from rich.progress import Progress

    from mocapqa.jobs.batch import BatchCounts
    from mocapqa.jobs.batch_output import ResultWriter
    from mocapqa.pipeline.options import AnalysisOptions

__all__ = ["DASK_LOGGERS", "batch", "quiet_dask_logging"]

DASK_LOGGERS = ("distributed", "distributed.client")
"""Dask's client-side loggers (each has its own level and handler)."""
MAX_FAILED_LINES = 50
"""Failed takes listed one per line on stderr at the end of a batch; the rest are counted."""


def quiet_dask_logging() -> None:
    """Set Dask's client-side loggers (:data:`DASK_LOGGERS`) to WARNING.

    Set in Dask's configuration, which distributed reads when it is first imported — only
    once a take is sent to a cluster, so that a batch with nothing left to analyse does not
    import it (0.8 CPU s of a resume, docs/batch.md) — and on the loggers themselves for a
    process that imported it already. Commands that use a Dask cluster (``mocapqa batch``,
    ``mocapqa limits build``) call it before they start.

    Notes
    -----
    Changes Dask's configuration (``logging``) and the loggers' levels of this process.
    """
    import dask.config

    levels = {name: "warning" for name in DASK_LOGGERS}
    dask.config.update(dask.config.config, {"logging": levels}, priority="new")
    for name in DASK_LOGGERS:
        logging.getLogger(name).setLevel(logging.WARNING)


def _options(text: str | None) -> Any:
    from mocapqa.errors import InputError
    from mocapqa.pipeline.options import AnalysisOptions

    if not text:
        return AnalysisOptions()
    try:
        data = json.loads(text)
    except ValueError as e:
        raise InputError(f"Expected --options to be a JSON object, got {text!r} ({e})") from e
    if not isinstance(data, dict):
        raise InputError(f"Expected --options to be a JSON object, got {text!r}")
    return AnalysisOptions.from_json(data)


@app.command()
def batch(
    paths: Annotated[list[Path], typer.Argument(help="Files and folders to analyse.")],
    shoot: Annotated[
        str | None, typer.Option(help="Shoot to put the new takes in (created when missing).")
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(help="Dask scheduler address (default: $MOCAPQA_DASK_SCHEDULER or local)."),
    ] = None,
    workers: Annotated[
        int, typer.Option(min=0, help="Worker processes of the local cluster (0: one per core).")
    ] = 0,
    options: Annotated[str | None, typer.Option(help="Run options as JSON.")] = None,
    output: Annotated[
        Path | None, typer.Option(help="Results table: .parquet, .csv or .jsonl.")
    ] = None,
) -> None:
    """Analyse every motion file under PATHS; one result row per file.

    Takes whose content, options and mocapqa version already have a done run are skipped, so
    an interrupted batch finishes when run again. Exit code 0 when no take failed, 2 when
    some did, 8 when the Dask scheduler cannot be reached or is lost. Each failed take is
    listed on stderr with its reason (the first 50; the full list is in --output).
    """
    from rich.console import Console

    from mocapqa.cli.outputs import FolderReads, check_outputs
    from mocapqa.config import get_settings
    from mocapqa.jobs.batch import MOTION_SUFFIXES
    from mocapqa.jobs.batch_output import ResultWriter
    from mocapqa.limits.catalog import ModelCatalog

    quiet_dask_logging()
    read = [FolderReads(p, MOTION_SUFFIXES, recursive=True) if p.is_dir() else p for p in paths]
    check_outputs({"--output": output}, read)
    run_options = _options(options)
    settings = get_settings()
    if run_options.limits_model is not None:  # refused before any take is read
        ModelCatalog.of_data_folder(settings.data_dir).require(run_options.limits_model)
    writer = ResultWriter(output) if output is not None else None
    address = scheduler or os.environ.get("MOCAPQA_DASK_SCHEDULER") or None
    console = Console(stderr=True)
    tally = _Tally(_progress_bar(console), writer)
    try:
        counts = _run(paths, shoot, run_options, address, workers, tally)
    finally:
        if writer is not None:
            writer.close()
    console.print(
        f"{counts.total} file(s): {counts.done} done, {counts.failed} failed, "
        f"{counts.skipped} skipped; {counts.frames} frames"
        + (f"; results in {output}" if output is not None else "")
    )
    _print_failed(console, tally.failed, counts.failed)
    if counts.failed:
        raise typer.Exit(2)


def _progress_bar(console: Console) -> Progress:
    """The batch's progress line: bar, count, tally, frame rate, elapsed time and ETA."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    return Progress(
        TextColumn("[bold]batch"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[tally]}"),
        TextColumn("{task.fields[rate]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=console,
    )


class _Tally:
    """The batch's rows as they come: counted on the progress line, written to the results
    table, and the first :data:`MAX_FAILED_LINES` failures kept to be listed."""

    def __init__(self, progress: Progress, writer: ResultWriter | None) -> None:
        self.progress = progress
        self.writer = writer
        self.task = progress.add_task("batch", total=None, tally="", rate="")
        self.state = {"done": 0, "failed": 0, "skipped": 0, "frames": 0}
        self.started = 0.0
        self.failed: list[tuple[str, str]] = []  # (source, reason)

    def on_total(self, total: int) -> None:
        """The number of rows to come: the clock starts."""
        self.started = time.perf_counter()
        self.progress.update(self.task, total=total)

    def on_row(self, row: dict[str, Any]) -> None:
        """One result row."""
        state = self.state
        state[row["status"]] += 1
        if row["status"] == "failed" and len(self.failed) < MAX_FAILED_LINES:
            reason = " ".join(str(row.get("error") or "no reason given").split("\n"))
            self.failed.append((str(row["source"]), reason))
        if row["status"] == "done":
            state["frames"] += int(row.get("n_frames") or 0)
        elapsed = max(time.perf_counter() - self.started, 1e-9)
        self.progress.update(
            self.task,
            advance=1,
            tally=f"done {state['done']} · failed {state['failed']} · skipped {state['skipped']}",
            rate=f"{state['frames'] / elapsed:,.0f} frames/s",
        )
        if self.writer is not None:
            self.writer.write(row)


def _run(
    paths: list[Path],
    shoot: str | None,
    run_options: AnalysisOptions,
    address: str | None,
    workers: int,
    tally: _Tally,
) -> BatchCounts:
    """Run the batch into the dashboard's database and data folder, on the cluster at
    ``address`` (a local one of ``workers`` processes when None).

    Raises
    ------
    ClusterError
        When the scheduler is lost, saying how many takes were stored before.
    """
    from mocapqa.config import get_settings
    from mocapqa.errors import ClusterError
    from mocapqa.jobs.batch import run_batch
    from mocapqa.jobs.engine import Engine
    from mocapqa.store.files import FileStore
    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore

    settings = get_settings()
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    FileStore(settings.data_dir)
    repository = Repository(settings.resolved_database_url)
    shoots = ShootStore(repository.engine)
    engine = Engine(address, workers or None)
    try:
        shoot_id = str(shoots.ensure(shoot)["id"]) if shoot else None
        with tally.progress:
            return run_batch(
                paths,
                shoots,
                run_options,
                tally.on_row,
                engine=engine,
                data_dir=settings.data_dir,
                shoot_id=shoot_id,
                on_total=tally.on_total,
            )
    except ClusterError as e:
        for name in DASK_LOGGERS:  # closing the lost client logs its reconnect loop's end
            logging.getLogger(name).setLevel(logging.CRITICAL)
        raise ClusterError(
            f"{e}; {tally.state['done']} take(s) analysed and stored, "
            "the same command finishes the rest once the scheduler is back"
        ) from e
    finally:
        engine.close()
        repository.close()


def _print_failed(console: Console, failed: list[tuple[str, str]], n_failed: int) -> None:
    """One line per failed take (``failed: SOURCE: REASON``), then how many more failed."""
    from rich.markup import escape

    for source, reason in failed:
        console.print(f"failed: {escape(source)}: {escape(reason)}", soft_wrap=True)
    if n_failed > len(failed):
        console.print(f"… and {n_failed - len(failed)} more failed", soft_wrap=True)
