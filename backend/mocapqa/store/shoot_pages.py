"""A shoot's take table: its filters, sort columns and pages.

Rows come from the ``take_qa`` read model (:data:`~mocapqa.store.take_listing.TABLE_ROWS`), so
the table sorts and filters on indexed columns without walking every run.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from sqlalchemy import and_, func, select
from sqlalchemy.sql.elements import ColumnElement

from mocapqa.errors import InputError
from mocapqa.pipeline.summary import SUMMARY_FIELDS
from mocapqa.store.repository import RUN_STATUSES
from mocapqa.store.rows import read_rows
from mocapqa.store.shoot_base import ShootTables
from mocapqa.store.tables import take_qa
from mocapqa.store.take_listing import TABLE_ROWS, checked_choice

__all__ = ["SORT_BY", "SORT_COLUMNS", "ShootPages", "TakeFilter"]

SORT_COLUMNS = (
    "name",
    "created_at",
    "status",
    *SUMMARY_FIELDS,
    "n_findings",
    "foot_skates",
    "foot_worst_skate",
    "foot_penetrations",
    "foot_floating",
    "foot_worst_skate_pct",
    "review_status",
    "reviewer",
)
"""Columns a shoot's take table can be sorted by. ``foot_worst_skate`` (cm, or % of the body
height for a take whose unit does not convert: ``foot_skate_unit``) sorts by
``foot_worst_skate_pct`` (:data:`SORT_BY`), the largest skate in % of the body height, which
means the same in every take."""
SORT_BY = {"foot_worst_skate": "foot_worst_skate_pct"}
"""A sort key → the column it sorts by, where they differ."""


class TakeFilter:
    """Filters of a shoot's take table (all optional, combined with AND).

    Parameters
    ----------
    status : str, optional
        Latest run status.
    review_status : str, optional
    rig : str, optional
    min_score, max_score : float, optional
        Inclusive QA score range.
    has_findings : bool, optional
        Only takes with (True) or without (False) findings.
    search : str, optional
        Case-insensitive substring of the take name.
    has_skates : bool, optional
        Only takes whose feet check found a foot skate (True) or found none (False; takes the
        feet check did not look at are in neither).
    """

    def __init__(
        self,
        status: str | None = None,
        review_status: str | None = None,
        rig: str | None = None,
        min_score: float | None = None,
        max_score: float | None = None,
        has_findings: bool | None = None,
        search: str | None = None,
        has_skates: bool | None = None,
    ) -> None:
        self.status = checked_choice("status", status, RUN_STATUSES)
        self.review_status = review_status
        self.rig = rig
        self.min_score = min_score
        self.max_score = max_score
        self.has_findings = has_findings
        self.search = search
        self.has_skates = has_skates

    def chosen(self) -> dict[str, Any]:
        """The filters that are set, by name (for an export to say what it holds)."""
        names = ("status", "review_status", "rig", "min_score", "max_score", "has_findings",
                 "search", "has_skates")  # fmt: skip
        return {n: getattr(self, n) for n in names if getattr(self, n) is not None}

    def clauses(self) -> list[ColumnElement[bool]]:
        """The SQL conditions."""
        found: list[ColumnElement[bool]] = []
        if self.status is not None:
            found.append(take_qa.c.status == self.status)
        if self.review_status is not None:
            found.append(take_qa.c.review_status == self.review_status)
        if self.rig is not None:
            found.append(take_qa.c.rig == self.rig)
        if self.min_score is not None:
            found.append(take_qa.c.score >= self.min_score)
        if self.max_score is not None:
            found.append(take_qa.c.score <= self.max_score)
        if self.has_findings is True:
            found.append(take_qa.c.n_findings > 0)
        elif self.has_findings is False:
            found.append(take_qa.c.n_findings == 0)
        if self.has_skates is True:
            found.append(take_qa.c.foot_skates > 0)
        elif self.has_skates is False:
            found.append(take_qa.c.foot_skates == 0)
        if self.search:
            pattern = "%" + self.search.lower().replace("%", r"\%").replace("_", r"\_") + "%"
            found.append(func.lower(take_qa.c.name).like(pattern, escape="\\"))
        return found


class ShootPages(ShootTables):
    """Pages of a shoot's take table (a part of :class:`~mocapqa.store.shoots.ShootStore`)."""

    def page(
        self,
        shoot_id: str,
        limit: int = 50,
        offset: int = 0,
        sort: str = "score",
        descending: bool = False,
        filters: TakeFilter | None = None,
    ) -> tuple[list[dict[str, Any]], int]:
        """A page of a shoot's takes (summary columns) and the total after filtering.

        Rows without a value in the sort column come last in either direction (ties, and
        those rows, by name then id).

        The page is found in two narrow steps, then read whole: the ids of the rows *with* a
        value, in order, from ``offset`` (an index range on ``(shoot_id, column)`` where there
        is one), then, if the page reaches past them, the ids of the rows without one, by name;
        only the page's rows are then read with their JSON and joined to ``takes``. Sorting
        whole rows (``ORDER BY score NULLS LAST`` over the shoot's rows with their per-joint
        JSON, joined before the offset is skipped) made SQLite's sorted pages several times
        slower (``docs/batch.md``).
        """
        if sort not in SORT_COLUMNS:
            raise InputError(f"Expected sort in {list(SORT_COLUMNS)}, got {sort!r}")
        self.require(shoot_id)
        where = and_(take_qa.c.shoot_id == shoot_id, *(filters or TakeFilter()).clauses())
        column = take_qa.c[SORT_BY.get(sort, sort)]
        ties = (take_qa.c.name, take_qa.c.take_id)
        with self.engine.connect() as conn:
            counted = conn.execute(select(func.count(), func.count(column)).where(where)).one()
            total, valued = int(counted[0]), int(counted[1])
            ids: list[str] = []
            if offset < valued:
                ids = list(
                    conn.execute(
                        select(take_qa.c.take_id)
                        .where(where, column.is_not(None))
                        .order_by(column.desc() if descending else column.asc(), *ties)
                        .limit(limit)
                        .offset(offset)
                    ).scalars()
                )
            if len(ids) < limit and total > valued:
                ids += conn.execute(
                    select(take_qa.c.take_id)
                    .where(where, column.is_(None))
                    .order_by(*ties)
                    .limit(limit - len(ids))
                    .offset(max(0, offset - valued))
                ).scalars()
            rows = read_rows(conn, TABLE_ROWS.where(take_qa.c.take_id.in_(ids)))
        found = {str(row["take_id"]): row for row in rows}
        return [found[i] for i in ids if i in found], total

    def rows(
        self,
        shoot_id: str,
        batch: int = 1000,
        filters: TakeFilter | None = None,
        sort: str = "name",
        descending: bool = False,
    ) -> Iterator[dict[str, Any]]:
        """The take rows of a shoot that pass ``filters`` (every row when None), in the order of
        :meth:`page`, read ``batch`` at a time (for exports)."""
        offset = 0
        while True:
            page, _ = self.page(shoot_id, batch, offset, sort, descending, filters)
            yield from page
            if len(page) < batch:
                return
            offset += batch
