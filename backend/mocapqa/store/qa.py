"""The ``take_qa`` rows: one per take, rebuilt from the take, its latest run and latest review.

The repository calls :func:`sync_take` in the same transaction as every write that changes one
of them (a new take or run, a run's status, a review), so the row is never stale.
"""

from __future__ import annotations

from typing import Any

from sqlalchemy import delete, insert, select
from sqlalchemy.engine import Connection

from mocapqa.pipeline.summary import SUMMARY_FIELDS
from mocapqa.store.tables import reviews, runs, take_qa, takes

__all__ = ["QA_COLUMNS", "lock_take", "qa_values", "sync_take"]

QA_COLUMNS = (*SUMMARY_FIELDS, "joint_violations")
"""Columns of ``take_qa`` copied from a done run's ``summary["qa"]``."""


def qa_values(take: dict[str, Any], run: dict[str, Any] | None) -> dict[str, Any]:
    """The summary columns of a take's row, from its latest run (None until it is done)."""
    values: dict[str, Any] = dict.fromkeys(QA_COLUMNS)
    values["n_frames"] = take["n_frames"]
    values["duration_s"] = take["n_frames"] / take["fps"] if take["fps"] else None
    values["n_findings"] = None
    if run is not None and run["status"] == "done" and isinstance(run["summary"], dict):
        qa = run["summary"].get("qa") or {}
        for column in QA_COLUMNS:
            if column in qa:
                values[column] = qa[column]
        values["n_findings"] = run["summary"].get("n_findings")
    return values


def lock_take(conn: Connection, take_id: str) -> Any:
    """Lock a take's row for the rest of the transaction; returns the row, or None if gone.

    One lock order for every writer (PostgreSQL; SQLite serialises writers anyway): the take
    first, then its runs, reviews and ``take_qa`` row. A writer that touched a run before the
    take (a run finishing) while another held the take and waited for that run (a delete)
    deadlocked; two writers rebuilding one take's QA row at once both inserted it.
    """
    return (
        conn.execute(select(takes).where(takes.c.id == take_id).with_for_update())
        .mappings()
        .first()
    )


def sync_take(conn: Connection, take_id: str) -> None:
    """Rebuild the ``take_qa`` row of one take (removes it when the take is gone).

    Callers that also change the take's runs or reviews call :func:`lock_take` first.
    """
    take = lock_take(conn, take_id)
    conn.execute(delete(take_qa).where(take_qa.c.take_id == take_id))
    if take is None:
        return
    run = (
        conn.execute(
            select(runs.c.id, runs.c.status, runs.c.summary)
            .where(runs.c.take_id == take_id)
            .order_by(runs.c.created_at.desc(), runs.c.id.desc())
            .limit(1)
        )
        .mappings()
        .first()
    )
    review = (
        conn.execute(
            select(reviews.c.status, reviews.c.reviewer)
            .where(reviews.c.take_id == take_id)
            .order_by(reviews.c.id.desc())
            .limit(1)
        )
        .mappings()
        .first()
    )
    run_row = dict(run) if run is not None else None
    conn.execute(
        insert(take_qa).values(
            take_id=take_id,
            shoot_id=take["shoot_id"],
            name=take["name"],
            kind=take["kind"],
            created_at=take["created_at"],
            run_id=run_row["id"] if run_row else None,
            status=run_row["status"] if run_row else None,
            review_status=review["status"] if review is not None else "unreviewed",
            reviewer=review["reviewer"] if review is not None else None,
            **qa_values(dict(take), run_row),
        )
    )
