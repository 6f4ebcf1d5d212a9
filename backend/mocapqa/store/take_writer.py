"""The one writer of new takes and runs: a take with its first run, or another run of a take.

A take and its first run are stored together, in the caller's transaction, with the take's
``take_qa`` row built from the values at hand (:func:`~mocapqa.store.qa.qa_row`): an upload's
take comes with a queued run (:func:`queued_run`), a batch's take with the done run its worker
made (:class:`DoneTake`, :func:`done_run`). A queued run's limits model is chosen by
:func:`~mocapqa.store.limits_runs.run_limits_model` (a batch chooses it once, before it starts).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import datetime
from typing import Any

from sqlalchemy import insert
from sqlalchemy.engine import Connection

from mocapqa import __version__
from mocapqa.store.limits_runs import run_limits_model
from mocapqa.store.qa import qa_row, sync_take
from mocapqa.store.tables import runs, take_qa, takes

__all__ = ["DoneTake", "add_run", "done_run", "queued_run", "write_takes"]


@dataclass(frozen=True)
class DoneTake:
    """A take analysed elsewhere (a batch's worker), to be stored with its done run.

    Parameters
    ----------
    take : dict
        The ``takes`` row's values (``id``, ``name``, ``sha256``, ``shoot_id``, ...).
    run_id : str
        The run's id.
    options : dict
        The run's options as JSON.
    summary : dict
        The run summary (:func:`mocapqa.jobs.runner.run_summary`).
    server_time_s : float
        The analysis's own time, seconds.
    """

    take: dict[str, Any]
    run_id: str
    options: dict[str, Any]
    summary: dict[str, Any]
    server_time_s: float


def _run_row(
    take: Mapping[str, Any], run_id: str, options: dict[str, Any], now: datetime
) -> dict[str, Any]:
    """The ``runs`` row of a new queued run of ``take`` (its ``id`` and ``sha256``)."""
    return {
        "id": run_id,
        "take_id": take["id"],
        "status": "queued",
        "progress": 0,
        "step": "queued",
        "options": options,
        "input_sha256": take["sha256"],
        "version": __version__,
        "created_at": now,
    }


def queued_run(
    conn: Connection,
    take: Mapping[str, Any],
    run_id: str,
    options: dict[str, Any],
    now: datetime,
) -> dict[str, Any]:
    """The ``runs`` row of a new queued run of ``take`` (its ``id``, ``sha256`` and
    ``shoot_id``), its options completed with the limits model the run checks with.

    Raises
    ------
    NotFoundError
        When the take's shoot is gone.
    """
    chosen = run_limits_model(conn, options.get("limits_model"), take.get("shoot_id"))
    return _run_row(take, run_id, {**options, "limits_model": chosen}, now)


def done_run(done: DoneTake, now: datetime) -> dict[str, Any]:
    """The ``runs`` row of a run finished elsewhere, started and finished ``now``."""
    return {
        **_run_row(done.take, done.run_id, done.options, now),
        "status": "done",
        "progress": 100,
        "step": "done",
        "summary": done.summary,
        "server_time_s": done.server_time_s,
        "started_at": now,
        "finished_at": now,
    }


def write_takes(
    conn: Connection,
    new: Sequence[tuple[Mapping[str, Any], Mapping[str, Any]]],
    now: datetime,
) -> None:
    """Insert new takes, each with its first run, and their ``take_qa`` rows.

    Each take is new (its id made by the caller), so its ``take_qa`` row is built from the
    values at hand (its only run, no review) instead of read back; the three tables get one
    multi-row insert each, a few statements for any number of takes.

    Parameters
    ----------
    conn : Connection
        In the caller's transaction.
    new : sequence of (mapping, mapping)
        Each take's ``takes`` values (``id`` included, ``created_at`` set here) and its run's
        row (:func:`queued_run` or :func:`done_run`). Every take's values have the same keys,
        and so have the runs' rows.
    now : datetime
        The takes' creation time.
    """
    if not new:
        return
    take_rows = [{**take, "created_at": now} for take, _ in new]
    run_rows = [dict(run) for _, run in new]
    conn.execute(insert(takes), take_rows)
    conn.execute(insert(runs), run_rows)
    qa_rows = [qa_row(take, run, None) for take, run in zip(take_rows, run_rows, strict=True)]
    conn.execute(insert(take_qa), qa_rows)


def add_run(
    conn: Connection, take: Mapping[str, Any], run_id: str, options: dict[str, Any], now: datetime
) -> None:
    """Queue another run of a stored take (locked by the caller) and rebuild its ``take_qa``
    row, in the caller's transaction."""
    conn.execute(insert(runs).values(**queued_run(conn, take, run_id, options, now)))
    sync_take(conn, str(take["id"]))
