"""A shoot's review queue: the analysed, unreviewed takes, lowest QA score first."""

from __future__ import annotations

from typing import Any

from sqlalchemy import and_, func, or_, select
from sqlalchemy.sql.elements import ColumnElement

from mocapqa.store.rows import read_rows
from mocapqa.store.shoot_base import ShootTables
from mocapqa.store.tables import take_qa
from mocapqa.store.take_listing import TABLE_ROWS

__all__ = ["ReviewQueue"]

_ORDER = (take_qa.c.score.asc().nulls_last(), take_qa.c.name, take_qa.c.take_id)
"""The review order: score ascending with missing scores last, then name, then take id."""


def _after_in_order(row: Any) -> ColumnElement[bool]:
    """Rows after ``row`` (its score, name and take id) in the review order (:data:`_ORDER`)."""
    same_score_later = or_(
        take_qa.c.name > row["name"],
        and_(take_qa.c.name == row["name"], take_qa.c.take_id > row["take_id"]),
    )
    if row["score"] is None:
        return and_(take_qa.c.score.is_(None), same_score_later)
    return or_(
        take_qa.c.score > row["score"],
        take_qa.c.score.is_(None),
        and_(take_qa.c.score == row["score"], same_score_later),
    )


class ReviewQueue(ShootTables):
    """The next take to review in a shoot (a part of :class:`~mocapqa.store.shoots.ShootStore`)."""

    def next_for_review(
        self, shoot_id: str, after: str | None = None
    ) -> tuple[dict[str, Any] | None, int]:
        """The unreviewed analysed take with the lowest score (ties by name), and how many
        unreviewed analysed takes remain.

        ``after`` (a take id) moves on without deciding: the take that follows it in that
        order, round to the first after the last, so skipping again and again visits every
        take waiting for review (None when ``after`` is the only one).
        """
        self.require(shoot_id)
        where = and_(
            take_qa.c.shoot_id == shoot_id,
            take_qa.c.status == "done",
            take_qa.c.review_status == "unreviewed",
        )
        first = TABLE_ROWS.order_by(*_ORDER).limit(1)
        with self.engine.connect() as conn:
            remaining = int(conn.execute(select(func.count()).where(where)).scalar_one())
            skipped = None
            if after is not None:
                skipped = (
                    conn.execute(
                        select(take_qa.c.score, take_qa.c.name, take_qa.c.take_id).where(
                            take_qa.c.shoot_id == shoot_id, take_qa.c.take_id == after
                        )
                    )
                    .mappings()
                    .first()
                )
            if skipped is None:
                found = read_rows(conn, first.where(where))
            else:
                found = read_rows(conn, first.where(where, _after_in_order(skipped)))
                if not found:  # past the last: round to the first that is not it
                    found = read_rows(conn, first.where(where, take_qa.c.take_id != after))
        return (found[0] if found else None), remaining
