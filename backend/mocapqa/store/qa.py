"""The ``take_qa`` rows: one per take, rebuilt from the take, its latest run and latest review.

A new take's row is built from the values at hand (:func:`qa_row`, by the take writer,
``store/take_writer.py``); after that the store calls :func:`sync_take` in the same transaction
as every write that changes one of its inputs (a new run, a run's status, a review, a move to
another shoot), so the row is never stale.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from sqlalchemy import delete, insert, select
from sqlalchemy.engine import Connection

from mocapqa.pipeline.summary import PCT_HEIGHT, SUMMARY_FIELDS
from mocapqa.store.tables import reviews, runs, take_qa, takes

__all__ = ["FEET_COLUMNS", "QA_COLUMNS", "lock_take", "qa_row", "qa_values", "sync_take"]

FEET_COLUMNS = (
    "foot_skates",
    "foot_worst_skate",
    "foot_skate_unit",
    "foot_penetrations",
    "foot_floating",
    "foot_worst_skate_pct",
)
"""The feet figures of a take's row: skate, penetration and floating counts, the largest
skate with its unit, and the largest skate in % of the estimated body height, the figure that
compares across takes (null when the run did not check the feet, or was made before the
figure was in the summary; last, so the columns before it keep their places in exports)."""
QA_COLUMNS = (*SUMMARY_FIELDS, *FEET_COLUMNS, "joint_violations")
"""Columns of ``take_qa`` copied from a done run's ``summary["qa"]``."""


def qa_values(take: Mapping[str, Any], run: Mapping[str, Any] | None) -> dict[str, Any]:
    """The summary columns of a take's row, from its latest run (None until it is done)."""
    values: dict[str, Any] = dict.fromkeys(QA_COLUMNS)
    values["n_frames"] = take["n_frames"]
    values["duration_s"] = take["n_frames"] / take["fps"] if take["fps"] else None
    values["n_findings"] = None
    if run is not None and run["status"] == "done" and isinstance(run.get("summary"), dict):
        qa = run["summary"].get("qa") or {}
        for column in QA_COLUMNS:
            if column in qa:
                values[column] = qa[column]
        values["n_findings"] = run["summary"].get("n_findings")
        if "foot_worst_skate_pct" not in qa and qa.get("foot_skate_unit") == PCT_HEIGHT:
            # A summary made before the figure: its largest skate is in % height already.
            values["foot_worst_skate_pct"] = qa.get("foot_worst_skate")
    return values


def qa_row(
    take: Mapping[str, Any], run: Mapping[str, Any] | None, review: Mapping[str, Any] | None
) -> dict[str, Any]:
    """A take's ``take_qa`` row.

    Parameters
    ----------
    take : mapping
        The ``takes`` row (``id``, ``shoot_id``, ``name``, ``kind``, ``created_at``,
        ``n_frames``, ``fps``).
    run : mapping, optional
        Its latest run (``id``, ``status``, ``summary``); None when it has none.
    review : mapping, optional
        Its latest review (``status``, ``reviewer``); None when it has none.
    """
    return {
        "take_id": take["id"],
        "shoot_id": take.get("shoot_id"),
        "name": take["name"],
        "kind": take["kind"],
        "created_at": take["created_at"],
        "run_id": run["id"] if run is not None else None,
        "status": run["status"] if run is not None else None,
        "review_status": review["status"] if review is not None else "unreviewed",
        "reviewer": review["reviewer"] if review is not None else None,
        **qa_values(take, run),
    }


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
    latest_run = dict(run) if run is not None else None
    latest_review = dict(review) if review is not None else None
    conn.execute(insert(take_qa).values(**qa_row(take, latest_run, latest_review)))
