"""Reviewers' accept / reject decisions on the corrections of a run, kept as history.

A run's decisions are on one kind of correction (:data:`DECIDED_ITEMS`): the twist intervals
of a motion take, or the swaps of a marker take; ``interval_id`` is the item's id within its
run. Beside them, a run's foot locks (the lock of each skate finding of its feet step, by the
finding's string id ``lock_id``, :data:`LOCK_ITEM`) are decided the same way; the column
``item_kind`` tells the two apart (:data:`ITEM_KINDS`). Every decision is a row (when, from
where, who, an optional note); the newest row of an item is its decision. Rows go with their
run (``ON DELETE CASCADE``).

A take whose review status is :data:`APPROVED` takes no decision: a decision never changes an
approved take (reopen it, with another review status, to decide again). A note is at most
:data:`NOTE_MAX_CHARS` characters; a run's history is read a page at a time
(:meth:`IntervalDecisions.history`, :meth:`IntervalDecisions.count`), while the decision of
each item is read from every row whatever their number (:meth:`IntervalDecisions.latest`).

Decisions are also labels: :meth:`IntervalDecisions.shoot_labels` gives a shoot's, from which
its later runs build their reviewer prior (:mod:`mocapqa.jobs.shoot_prior`). Only decisions
on runs of the twist method :data:`CALIBRATED_METHOD` are labels: the paper's method scores
no calibrated probability.
"""

from __future__ import annotations

from typing import Any, Literal, get_args

from sqlalchemy import func, insert, select
from sqlalchemy.engine import Connection
from sqlalchemy.exc import IntegrityError

from mocapqa.errors import ConflictError, InputError, NotFoundError, OptionError
from mocapqa.store.access import TableAccess
from mocapqa.store.qa import lock_take
from mocapqa.store.rows import plain, read_rows
from mocapqa.store.stamps import utc_now
from mocapqa.store.tables import interval_decisions, runs, take_qa, takes
from mocapqa.store.take_listing import REVIEW_STATUS

__all__ = [
    "APPROVED",
    "CALIBRATED_METHOD",
    "CORRECTION_ITEM",
    "DECIDED_ITEMS",
    "INTERVAL_DECISIONS",
    "ITEM_KINDS",
    "LOCK_ITEM",
    "NOTE_MAX_CHARS",
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
APPROVED = "approved"
"""The review status of a take no decision changes."""
CALIBRATED_METHOD = "robust"
"""The twist method whose intervals carry a calibrated probability (a run's
``options["twist_method"]``, this when absent): only decisions on its runs are labels."""
NOTE_MAX_CHARS = 4000
"""The longest note a decision keeps, in characters."""


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
        """Append one decision row, in one transaction with the checks that its run and take
        exist (a take deleted meanwhile answers :class:`NotFoundError`, never a foreign key
        error) and that the take is not approved.

        Raises
        ------
        InputError
            For a decision not in :data:`INTERVAL_DECISIONS`, or a note longer than
            :data:`NOTE_MAX_CHARS` (an :class:`OptionError` naming ``note``).
        NotFoundError
            If the run or its take no longer exists.
        ConflictError
            If the run's take is approved.
        """
        if decision not in INTERVAL_DECISIONS:
            raise InputError(f"Expected decision in {list(INTERVAL_DECISIONS)}, got {decision!r}")
        if len(note) > NOTE_MAX_CHARS:
            raise OptionError(
                "note", f"Expected at most {NOTE_MAX_CHARS} characters, got {len(note)}"
            )
        values = {
            "run_id": run_id,
            **item,
            "decision": decision,
            "note": note,
            "reviewer": reviewer or "anonymous",
            "client": client[:255],
            "created_at": utc_now(),
        }
        gone = NotFoundError(f"Expected run {run_id!r} and its take to exist, got none")
        try:
            with self.engine.begin() as conn:
                _check_open(conn, run_id, gone)
                result = conn.execute(
                    insert(interval_decisions).values(**values).returning(interval_decisions)
                )
                return plain(result.mappings().one())
        except IntegrityError as error:  # the run's foreign key: its take was deleted meanwhile
            raise gone from error

    def history(
        self,
        run_id: str,
        kind: ItemKind = CORRECTION_ITEM,
        limit: int | None = None,
        offset: int = 0,
    ) -> list[dict[str, Any]]:
        """The decisions on a run's items of ``kind`` (its twist intervals or swaps, or its
        foot locks), newest first: ``limit`` of them (every one when None) after skipping
        the ``offset`` newest."""
        table = interval_decisions
        query = (
            select(table)
            .where(table.c.run_id == run_id, table.c.item_kind == kind)
            .order_by(table.c.id.desc())
            .offset(offset)
            .limit(limit)
        )
        with self.engine.connect() as conn:
            return read_rows(conn, query)

    def count(self, run_id: str, kind: ItemKind = CORRECTION_ITEM) -> int:
        """How many decisions a run's items of ``kind`` have had (its history's length)."""
        table = interval_decisions
        query = (
            select(func.count())
            .select_from(table)
            .where(table.c.run_id == run_id, table.c.item_kind == kind)
        )
        with self.engine.connect() as conn:
            return int(conn.execute(query).scalar_one())

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
        among its runs of the twist method :data:`CALIBRATED_METHOD` (a take decided, re-run
        and decided again gives the new run's labels only). Decisions on a run of another
        method (the paper's, with no calibrated probability) and foot lock decisions are not
        labels and count for neither.

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
                runs.c.take_id, runs.c.summary, runs.c.options,
                REVIEW_STATUS.label("review_status"),
            )
            .join(newest, table.c.id == newest.c.id)
            .join(runs, runs.c.id == table.c.run_id)
            .outerjoin(take_qa, take_qa.c.take_id == runs.c.take_id)
            .order_by(table.c.id)
        )  # fmt: skip
        with self.engine.connect() as conn:
            rows = [r for r in conn.execute(query).all() if _calibrated(r.options)]
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


def _check_open(conn: Connection, run_id: str, gone: NotFoundError) -> None:
    """Check, in the transaction that writes a decision, that the run and its take exist and
    that the take is not approved; the take's row stays locked to the transaction's end (a
    review or a delete of the take waits for it, PostgreSQL).

    Raises
    ------
    NotFoundError
        ``gone``, if the run or its take no longer exists.
    ConflictError
        If the take's review status is :data:`APPROVED`.
    """
    take_id = conn.execute(select(runs.c.take_id).where(runs.c.id == run_id)).scalar()
    if take_id is None or lock_take(conn, str(take_id)) is None:
        raise gone
    status = conn.execute(
        select(take_qa.c.review_status).where(take_qa.c.take_id == take_id)
    ).scalar()
    if status == APPROVED:
        raise ConflictError(
            f"Expected a take that is not approved to decide on, got take {take_id} approved: "
            "reopen it (a review of another status) to change decisions"
        )


def _calibrated(options: Any) -> bool:
    """Whether a run of ``options`` (its stored JSON) scored its twist intervals with a
    calibrated probability: its twist method is :data:`CALIBRATED_METHOD`."""
    method = options.get("twist_method") if isinstance(options, dict) else None
    return method in (None, CALIBRATED_METHOD)


def _rig_of(summary: Any) -> str:
    """The rig family in a run's summary (``summary["qa"]["rig"]``), "" without one."""
    qa = summary.get("qa") if isinstance(summary, dict) else None
    rig = qa.get("rig") if isinstance(qa, dict) else None
    return str(rig) if rig else ""
