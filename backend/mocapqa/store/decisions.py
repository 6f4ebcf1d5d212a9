"""Reviewers' accept / reject decisions on the corrections of a run, kept as history.

A run's decisions are on one kind of correction (:data:`DECIDED_ITEMS`): the twist intervals
of a motion take, or the swaps of a marker take; ``interval_id`` is the item's id within its
run. Every decision is a row (when, from where, who, an optional note); the newest row of an
item is its decision. Rows go with their run (``ON DELETE CASCADE``).

Decisions are also labels: :meth:`IntervalDecisions.shoot_labels` gives a shoot's, from which
its later runs build their reviewer prior (:mod:`mocapqa.jobs.shoot_prior`).
"""

from __future__ import annotations

from typing import Any, Literal, get_args

from sqlalchemy import func, insert, select

from mocapqa.errors import InputError
from mocapqa.store.access import TableAccess
from mocapqa.store.rows import plain, read_rows
from mocapqa.store.stamps import utc_now
from mocapqa.store.tables import interval_decisions, runs, take_qa, takes
from mocapqa.store.take_listing import REVIEW_STATUS

__all__ = [
    "DECIDED_ITEMS",
    "INTERVAL_DECISIONS",
    "DecidedItem",
    "Decision",
    "IntervalDecisions",
]

Decision = Literal["accept", "reject"]
"""What a reviewer can decide about one correction (a twist interval or a swap)."""
INTERVAL_DECISIONS: tuple[Decision, ...] = get_args(Decision)
"""The values of :data:`Decision`."""
DecidedItem = Literal["interval", "swap"]
"""The corrections a reviewer decides on: a motion take's twist intervals, a marker take's
swaps."""
DECIDED_ITEMS: tuple[DecidedItem, ...] = get_args(DecidedItem)
"""The values of :data:`DecidedItem`."""


class IntervalDecisions(TableAccess):
    """Reads and writes of :data:`~mocapqa.store.tables.interval_decisions`."""

    def add(
        self, run_id: str, interval_id: int, decision: str, note: str, reviewer: str, client: str
    ) -> dict[str, Any]:
        """Append a decision to a run's history and return its row.

        Raises
        ------
        InputError
            For a decision not in :data:`INTERVAL_DECISIONS`.
        """
        if decision not in INTERVAL_DECISIONS:
            raise InputError(f"Expected decision in {list(INTERVAL_DECISIONS)}, got {decision!r}")
        with self.engine.begin() as conn:
            result = conn.execute(
                insert(interval_decisions)
                .values(
                    run_id=run_id,
                    interval_id=interval_id,
                    decision=decision,
                    note=note,
                    reviewer=reviewer or "anonymous",
                    client=client[:255],
                    created_at=utc_now(),
                )
                .returning(interval_decisions)
            )
            return plain(result.mappings().one())

    def history(self, run_id: str) -> list[dict[str, Any]]:
        """Every decision on a run's items, newest first."""
        table = interval_decisions
        with self.engine.connect() as conn:
            return read_rows(
                conn, select(table).where(table.c.run_id == run_id).order_by(table.c.id.desc())
            )

    def latest(self, run_id: str) -> dict[int, str]:
        """Item id → its newest decision, for the items (intervals or swaps) that have one."""
        table = interval_decisions
        newest = (
            select(func.max(table.c.id).label("id"))
            .where(table.c.run_id == run_id)
            .group_by(table.c.interval_id)
            .subquery()
        )
        with self.engine.connect() as conn:
            rows = conn.execute(
                select(table.c.interval_id, table.c.decision).join(
                    newest, table.c.id == newest.c.id
                )
            ).all()
        return {int(r.interval_id): str(r.decision) for r in rows}

    def shoot_labels(self, shoot_id: str) -> list[dict[str, Any]]:
        """The labels a shoot's reviewers gave: for each take of the shoot, the newest decision
        of each twist interval (or swap) of its decided run, the run of its newest decision
        (a take decided, re-run and decided again gives the new run's labels only).

        Returns
        -------
        list of dict
            ``take_id``, ``run_id``, ``interval_id``, ``decision``, the take's
            ``review_status`` (``"unreviewed"`` before any review) and the decided run's
            ``rig`` family (its summary's, "" when it has none), by take, then item id.
        """
        table = interval_decisions
        newest = (
            select(func.max(table.c.id).label("id"))
            .join(runs, runs.c.id == table.c.run_id)
            .join(takes, takes.c.id == runs.c.take_id)
            .where(takes.c.shoot_id == shoot_id)
            .group_by(table.c.run_id, table.c.interval_id)
            .subquery()
        )
        query = (
            select(
                table.c.id, table.c.run_id, table.c.interval_id, table.c.decision,
                runs.c.take_id, runs.c.summary, REVIEW_STATUS.label("review_status"),
            )
            .join(newest, table.c.id == newest.c.id)
            .join(runs, runs.c.id == table.c.run_id)
            .outerjoin(take_qa, take_qa.c.take_id == runs.c.take_id)
            .order_by(table.c.id)
        )  # fmt: skip
        with self.engine.connect() as conn:
            rows = conn.execute(query).all()
        decided_run = {str(r.take_id): str(r.run_id) for r in rows}  # the newest wins
        return sorted(
            (
                {
                    "take_id": str(r.take_id),
                    "run_id": str(r.run_id),
                    "interval_id": int(r.interval_id),
                    "decision": str(r.decision),
                    "review_status": str(r.review_status),
                    "rig": _rig_of(r.summary),
                }
                for r in rows
                if decided_run[str(r.take_id)] == str(r.run_id)
            ),
            key=lambda label: (label["take_id"], label["interval_id"]),
        )


def _rig_of(summary: Any) -> str:
    """The rig family in a run's summary (``summary["qa"]["rig"]``), "" without one."""
    qa = summary.get("qa") if isinstance(summary, dict) else None
    rig = qa.get("rig") if isinstance(qa, dict) else None
    return str(rig) if rig else ""
