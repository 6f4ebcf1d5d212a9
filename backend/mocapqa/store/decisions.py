"""Reviewers' accept / reject decisions on the corrections of a run, kept as history.

A run's decisions are on one kind of correction (:data:`DECIDED_ITEMS`): the twist intervals
of a motion take, or the swaps of a marker take; ``interval_id`` is the item's id within its
run. Beside them, a run's foot locks (the lock of each skate finding of its feet step, by the
finding's string id ``lock_id``, :data:`LOCK_ITEM`) are decided the same way; the column
``item_kind`` tells the two apart (:data:`ITEM_KINDS`). Every decision is a row (when, from
where, who, an optional note); the newest row of an item is its decision. Rows go with their
run (``ON DELETE CASCADE``).

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
    "CORRECTION_ITEM",
    "DECIDED_ITEMS",
    "INTERVAL_DECISIONS",
    "ITEM_KINDS",
    "LOCK_ITEM",
    "DecidedItem",
    "Decision",
    "IntervalDecisions",
    "ItemKind",
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
ItemKind = Literal["correction", "lock"]
"""What a stored decision is on (the ``item_kind`` column): the run's correction (a
:data:`DecidedItem`, by ``interval_id``) or a foot lock (by ``lock_id``)."""
ITEM_KINDS: tuple[ItemKind, ...] = get_args(ItemKind)
"""The values of :data:`ItemKind`."""
CORRECTION_ITEM: ItemKind = "correction"
"""The ``item_kind`` of a twist interval's or a swap's decision (every row before locks)."""
LOCK_ITEM: ItemKind = "lock"
"""The ``item_kind`` of a foot lock's decision."""


class IntervalDecisions(TableAccess):
    """Reads and writes of :data:`~mocapqa.store.tables.interval_decisions`."""

    def add(
        self, run_id: str, interval_id: int, decision: str, note: str, reviewer: str, client: str
    ) -> dict[str, Any]:
        """Append a decision on a twist interval or swap to a run's history and return its row.

        Raises
        ------
        InputError
            For a decision not in :data:`INTERVAL_DECISIONS`.
        """
        item = {"item_kind": CORRECTION_ITEM, "interval_id": interval_id, "lock_id": None}
        return self._insert(run_id, item, decision, note, reviewer, client)

    def add_lock(
        self, run_id: str, lock_id: str, decision: str, note: str, reviewer: str, client: str
    ) -> dict[str, Any]:
        """Append a decision on a foot lock (a skate finding's id, ``skate-left-120``) to a
        run's history and return its row.

        Raises
        ------
        InputError
            For a decision not in :data:`INTERVAL_DECISIONS` or an empty id.
        """
        if not lock_id or len(lock_id) > 64:
            raise InputError(f"Expected a foot lock id of 1 to 64 characters, got {lock_id!r}")
        item = {"item_kind": LOCK_ITEM, "interval_id": None, "lock_id": lock_id}
        return self._insert(run_id, item, decision, note, reviewer, client)

    def _insert(
        self,
        run_id: str,
        item: dict[str, Any],
        decision: str,
        note: str,
        reviewer: str,
        client: str,
    ) -> dict[str, Any]:
        if decision not in INTERVAL_DECISIONS:
            raise InputError(f"Expected decision in {list(INTERVAL_DECISIONS)}, got {decision!r}")
        with self.engine.begin() as conn:
            result = conn.execute(
                insert(interval_decisions)
                .values(
                    run_id=run_id,
                    **item,
                    decision=decision,
                    note=note,
                    reviewer=reviewer or "anonymous",
                    client=client[:255],
                    created_at=utc_now(),
                )
                .returning(interval_decisions)
            )
            return plain(result.mappings().one())

    def history(self, run_id: str, kind: ItemKind = CORRECTION_ITEM) -> list[dict[str, Any]]:
        """Every decision on a run's items of ``kind`` (its twist intervals or swaps, or its
        foot locks), newest first."""
        table = interval_decisions
        query = (
            select(table)
            .where(table.c.run_id == run_id, table.c.item_kind == kind)
            .order_by(table.c.id.desc())
        )
        with self.engine.connect() as conn:
            return read_rows(conn, query)

    def latest(self, run_id: str) -> dict[int, str]:
        """Item id → its newest decision, for the items (intervals or swaps) that have one."""
        rows = self._newest(run_id, CORRECTION_ITEM, interval_decisions.c.interval_id)
        return {int(key): decision for key, decision in rows}

    def latest_locks(self, run_id: str) -> dict[str, str]:
        """Foot lock id → its newest decision, for the locks that have one."""
        rows = self._newest(run_id, LOCK_ITEM, interval_decisions.c.lock_id)
        return {str(key): decision for key, decision in rows}

    def _newest(self, run_id: str, kind: ItemKind, key: Any) -> list[tuple[Any, str]]:
        """(item key, newest decision) of each item of ``kind`` of a run."""
        table = interval_decisions
        newest = (
            select(func.max(table.c.id).label("id"))
            .where(table.c.run_id == run_id, table.c.item_kind == kind)
            .group_by(key)
            .subquery()
        )
        with self.engine.connect() as conn:
            rows = conn.execute(
                select(key, table.c.decision).join(newest, table.c.id == newest.c.id)
            ).all()
        return [(r[0], str(r[1])) for r in rows]

    def shoot_labels(self, shoot_id: str) -> list[dict[str, Any]]:
        """The labels a shoot's reviewers gave: for each take of the shoot, the newest decision
        of each twist interval (or swap) of its decided run, the run of its newest decision
        (a take decided, re-run and decided again gives the new run's labels only). Foot
        lock decisions are not labels and count for neither.

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
            .where(takes.c.shoot_id == shoot_id, table.c.item_kind == CORRECTION_ITEM)
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
