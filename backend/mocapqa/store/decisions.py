"""Reviewers' accept / reject decisions on the corrections of a run, kept as history.

A run's decisions are on one kind of correction (:data:`DECIDED_ITEMS`): the twist intervals
of a motion take, or the swaps of a marker take; ``interval_id`` is the item's id within its
run. Every decision is a row (when, from where, who, an optional note); the newest row of an
item is its decision. Rows go with their run (``ON DELETE CASCADE``).
"""

from __future__ import annotations

from typing import Any, Literal, get_args

from sqlalchemy import func, insert, select

from mocapqa.errors import InputError
from mocapqa.store.access import TableAccess
from mocapqa.store.rows import plain, read_rows
from mocapqa.store.stamps import utc_now
from mocapqa.store.tables import interval_decisions

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
