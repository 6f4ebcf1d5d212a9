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
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from mocapqa.cli.app import app

if TYPE_CHECKING:
    from rich.console import Console

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
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from mocapqa.cli.outputs import FolderReads, check_outputs
    from mocapqa.config import get_settings
    from mocapqa.errors import ClusterError
    from mocapqa.jobs.batch import MOTION_SUFFIXES, run_batch
    from mocapqa.jobs.batch_output import ResultWriter
    from mocapqa.jobs.engine import Engine
    from mocapqa.limits.catalog import ModelCatalog
    from mocapqa.store.files import FileStore
    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore

    quiet_dask_logging()
    read = [FolderReads(p, MOTION_SUFFIXES, recursive=True) if p.is_dir() else p for p in paths]
    check_outputs({"--output": output}, read)
    run_options = _options(options)
    settings = get_settings()
    if run_options.limits_model is not None:  # refused before any take is read
        ModelCatalog.of_data_folder(settings.data_dir).require(run_options.limits_model)
    writer = ResultWriter(output) if output is not None else None
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    FileStore(settings.data_dir)
    repository = Repository(settings.resolved_database_url)
    shoots = ShootStore(repository.engine)
    shoot_id = str(shoots.ensure(shoot)["id"]) if shoot else None
    address = scheduler or os.environ.get("MOCAPQA_DASK_SCHEDULER") or None
    engine = Engine(address, workers or None)
    console = Console(stderr=True)
    progress = Progress(
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
    task = progress.add_task("batch", total=None, tally="", rate="")
    state = {"done": 0, "failed": 0, "skipped": 0, "frames": 0, "started": 0.0}
    failed: list[tuple[str, str]] = []  # (source, reason) of the first MAX_FAILED_LINES

    def on_total(total: int) -> None:
        import time

        state["started"] = time.perf_counter()
        progress.update(task, total=total)

    def on_row(row: dict[str, Any]) -> None:
        import time

        state[row["status"]] += 1
        if row["status"] == "failed" and len(failed) < MAX_FAILED_LINES:
            reason = " ".join(str(row.get("error") or "no reason given").split("\n"))
            failed.append((str(row["source"]), reason))
        if row["status"] == "done":
            state["frames"] += int(row.get("n_frames") or 0)
        elapsed = max(time.perf_counter() - state["started"], 1e-9)
        progress.update(
            task,
            advance=1,
            tally=f"done {state['done']} · failed {state['failed']} · skipped {state['skipped']}",
            rate=f"{state['frames'] / elapsed:,.0f} frames/s",
        )
        if writer is not None:
            writer.write(row)

    try:
        with progress:
            counts = run_batch(
                paths,
                shoots,
                run_options,
                on_row,
                engine=engine,
                data_dir=settings.data_dir,
                shoot_id=shoot_id,
                on_total=on_total,
            )
    except ClusterError as e:
        for name in DASK_LOGGERS:  # closing the lost client logs its reconnect loop's end
            logging.getLogger(name).setLevel(logging.CRITICAL)
        raise ClusterError(
            f"{e}; {state['done']} take(s) analysed and stored, "
            "the same command finishes the rest once the scheduler is back"
        ) from e
    finally:
        if writer is not None:
            writer.close()
        engine.close()
        repository.close()
    console.print(
        f"{counts.total} file(s): {counts.done} done, {counts.failed} failed, "
        f"{counts.skipped} skipped; {counts.frames} frames"
        + (f"; results in {output}" if output is not None else "")
    )
    _print_failed(console, failed, counts.failed)
    if counts.failed:
        raise typer.Exit(2)


def _print_failed(console: Console, failed: list[tuple[str, str]], n_failed: int) -> None:
    """One line per failed take (``failed: SOURCE: REASON``), then how many more failed."""
    from rich.markup import escape

    for source, reason in failed:
        console.print(f"failed: {escape(source)}: {escape(reason)}", soft_wrap=True)
    if n_failed > len(failed):
        console.print(f"… and {n_failed - len(failed)} more failed", soft_wrap=True)
