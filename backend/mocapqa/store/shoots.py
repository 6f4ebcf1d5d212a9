"""Shoots: named collections of takes, their take table, heat map, review queue and progress.

Reads go to the ``take_qa`` rows (one per take, kept in step by the repository), so a shoot's
table sorts and filters on indexed columns without walking every run.
"""

from __future__ import annotations

import unicodedata
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from sqlalchemy import Connection, Engine, and_, delete, func, insert, or_, select, update
from sqlalchemy.exc import IntegrityError
from sqlalchemy.sql.elements import ColumnElement

from mocapqa import __version__
from mocapqa.core.text import display_name
from mocapqa.errors import ConflictError, InputError, NotFoundError
from mocapqa.pipeline.summary import SUMMARY_FIELDS
from mocapqa.store.limits_runs import stale_limits_counts
from mocapqa.store.qa import qa_values, sync_take
from mocapqa.store.repository import RUN_STATUSES, new_id, utc_now
from mocapqa.store.rows import plain
from mocapqa.store.tables import reviews, runs, shoots, source_hashes, take_qa, takes

__all__ = ["SORT_COLUMNS", "DoneTake", "ShootStore", "TakeFilter"]

SORT_COLUMNS = (
    "name",
    "created_at",
    "status",
    *SUMMARY_FIELDS,
    "n_findings",
    "review_status",
    "reviewer",
)
"""Columns a shoot's take table can be sorted by."""


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
    ) -> None:
        if status is not None and status not in RUN_STATUSES:
            raise InputError(f"Expected status in {list(RUN_STATUSES)}, got {status!r}")
        self.status = status
        self.review_status = review_status
        self.rig = rig
        self.min_score = min_score
        self.max_score = max_score
        self.has_findings = has_findings
        self.search = search

    def chosen(self) -> dict[str, Any]:
        """The filters that are set, by name (for an export to say what it holds)."""
        names = ("status", "review_status", "rig", "min_score", "max_score", "has_findings",
                 "search")  # fmt: skip
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
        if self.search:
            pattern = "%" + self.search.lower().replace("%", r"\%").replace("_", r"\_") + "%"
            found.append(func.lower(take_qa.c.name).like(pattern, escape="\\"))
        return found


def _after_in_order(row: Any) -> ColumnElement[bool]:
    """Rows after ``row`` (its score, name and take id) in the review order: score ascending
    with missing scores last, then name, then take id."""
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


class ShootStore:
    """Database access for shoots and their take tables.

    Parameters
    ----------
    engine : Engine
        The repository's engine (its schema already created).
    """

    def __init__(self, engine: Engine) -> None:
        self.engine = engine

    # shoots ----------------------------------------------------------------------------
    def create(self, name: str, owner_id: int | None = None) -> dict[str, Any]:
        """A new empty shoot owned by ``owner_id`` (None: no owner, only admins may rename
        or delete it); :class:`ConflictError` when the name is taken."""
        clean = _checked_name(name)
        row = {"id": new_id(), "name": clean, "created_at": utc_now(), "owner_id": owner_id}
        try:
            with self.engine.begin() as conn:
                _refuse_taken(conn, clean)
                conn.execute(insert(shoots).values(**row))
        except IntegrityError as e:
            raise ConflictError(f"Expected a new shoot name, got {clean!r} (taken)") from e
        return self.get(str(row["id"]))

    def ensure(self, name: str) -> dict[str, Any]:
        """The shoot of that name (or of a name differing only in case), created when
        missing."""
        clean = _checked_name(name)  # the form it is stored in
        with self.engine.connect() as conn:
            found = _same_name(conn, clean)
        if found is not None:
            return self.get(found[0])
        try:
            return self.create(name)
        except ConflictError:  # created meanwhile by another process
            return self.ensure(name)

    def rename(self, shoot_id: str, name: str) -> dict[str, Any]:
        """Give a shoot a new (unused) name."""
        clean = _checked_name(name)
        self.get(shoot_id)
        try:
            with self.engine.begin() as conn:
                _refuse_taken(conn, clean, shoot_id)
                conn.execute(update(shoots).where(shoots.c.id == shoot_id).values(name=clean))
        except IntegrityError as e:
            raise ConflictError(f"Expected a new shoot name, got {clean!r} (taken)") from e
        return self.get(shoot_id)

    def set_limits_model(self, shoot_id: str, name: str) -> dict[str, Any]:
        """Give a shoot the limits model ``name`` (checked by the caller against the catalog);
        runs recorded from now on for its takes use it."""
        self.require(shoot_id)
        with self.engine.begin() as conn:
            conn.execute(update(shoots).where(shoots.c.id == shoot_id).values(limits_model=name))
        return self.get(shoot_id)

    def limits_model(self, shoot_id: str) -> str:
        """The name of a shoot's limits model; :class:`NotFoundError` when it is missing."""
        with self.engine.connect() as conn:
            query = select(shoots.c.limits_model).where(shoots.c.id == shoot_id)
            found = conn.execute(query).scalar()
        if found is None:
            raise NotFoundError(f"Expected shoot {shoot_id!r} to exist, got none")
        return str(found)

    def require(self, shoot_id: str) -> None:
        """:class:`NotFoundError` unless the shoot exists (one indexed lookup, no counts)."""
        with self.engine.connect() as conn:
            found = conn.execute(select(shoots.c.id).where(shoots.c.id == shoot_id)).first()
        if found is None:
            raise NotFoundError(f"Expected shoot {shoot_id!r} to exist, got none")

    def get(self, shoot_id: str) -> dict[str, Any]:
        """One shoot with its counts; :class:`NotFoundError` when missing."""
        found = self._with_counts(shoot_id)
        if not found:
            raise NotFoundError(f"Expected shoot {shoot_id!r} to exist, got none")
        return found[0]

    def list_all(self) -> list[dict[str, Any]]:
        """Every shoot, by name, with counts per run status and per review status."""
        return self._with_counts(None)

    def _with_counts(self, shoot_id: str | None) -> list[dict[str, Any]]:
        query = select(shoots).order_by(shoots.c.name)
        counts = select(
            take_qa.c.shoot_id,
            take_qa.c.status,
            take_qa.c.review_status,
            func.count().label("n"),
            func.coalesce(func.sum(take_qa.c.n_frames), 0).label("frames"),
        ).group_by(take_qa.c.shoot_id, take_qa.c.status, take_qa.c.review_status)
        if shoot_id is not None:
            query = query.where(shoots.c.id == shoot_id)
            counts = counts.where(take_qa.c.shoot_id == shoot_id)
        else:
            counts = counts.where(take_qa.c.shoot_id.is_not(None))
        with self.engine.connect() as conn:
            rows = [plain(r) for r in conn.execute(query).mappings()]
            tallies = list(conn.execute(counts).mappings())
        by_id = {row["id"]: row for row in rows}
        stale = stale_limits_counts(self.engine, shoot_id)
        for row in rows:
            row["limits_stale_takes"] = stale.get(str(row["id"]), 0)
            row["n_takes"] = 0
            row["n_frames"] = 0
            row["status_counts"] = {s: 0 for s in RUN_STATUSES}
            row["review_counts"] = {}
        for tally in tallies:
            shoot = by_id.get(tally["shoot_id"])
            if shoot is None:
                continue
            n = int(tally["n"])
            shoot["n_takes"] += n
            shoot["n_frames"] += int(tally["frames"])
            status = tally["status"] or "queued"
            shoot["status_counts"][status] = shoot["status_counts"].get(status, 0) + n
            review = tally["review_status"]
            shoot["review_counts"][review] = shoot["review_counts"].get(review, 0) + n
        return rows

    def delete(self, shoot_id: str) -> tuple[list[str], list[str]]:
        """Delete a shoot with its takes, runs and reviews; returns (take ids, run ids)."""
        self.get(shoot_id)
        with self.engine.begin() as conn:
            # Lock the shoot first, so no take is added between listing its takes and deleting
            # them (its files would be left behind): FOR UPDATE blocks PostgreSQL's foreign-key
            # check of a new take, and the write takes SQLite's one write lock now.
            conn.execute(select(shoots.c.id).where(shoots.c.id == shoot_id).with_for_update())
            conn.execute(update(shoots).where(shoots.c.id == shoot_id).values(name=shoots.c.name))
            take_ids = [
                str(t)
                for t in conn.execute(select(takes.c.id).where(takes.c.shoot_id == shoot_id))
                .scalars()
                .all()
            ]
            in_shoot = select(takes.c.id).where(takes.c.shoot_id == shoot_id)
            run_ids = [
                str(r)
                for r in conn.execute(select(runs.c.id).where(runs.c.take_id.in_(in_shoot)))
                .scalars()
                .all()
            ]
            conn.execute(delete(take_qa).where(take_qa.c.take_id.in_(in_shoot)))
            conn.execute(delete(reviews).where(reviews.c.take_id.in_(in_shoot)))
            conn.execute(delete(runs).where(runs.c.take_id.in_(in_shoot)))
            conn.execute(delete(takes).where(takes.c.shoot_id == shoot_id))
            conn.execute(delete(shoots).where(shoots.c.id == shoot_id))
        return take_ids, run_ids

    # the take table --------------------------------------------------------------------
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
        column = take_qa.c[sort]
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
            found = {
                str(r["take_id"]): plain(r)
                for r in conn.execute(
                    select(take_qa, takes.c.format, takes.c.fps, takes.c.n_joints)
                    .join(takes, takes.c.id == take_qa.c.take_id)
                    .where(take_qa.c.take_id.in_(ids))
                ).mappings()
            }
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

    def heatmap(
        self,
        shoot_id: str,
        limit: int = 200,
        offset: int = 0,
        sort: str = "score",
        descending: bool = False,
        filters: TakeFilter | None = None,
    ) -> dict[str, Any]:
        """Joint × take share of frames outside the limits, for a page of the shoot's takes
        (in the order and with the filters of :meth:`page`).

        Returns
        -------
        dict
            ``joints`` (those with any violation on the page, most violated first), ``takes``
            (``{"take_id", "name", "score"}`` in table order) and ``values`` (``joints × takes``
            shares in [0, 1]; 0 where none, None where the limits check did not run) and
            ``total`` (takes in the shoot that pass ``filters``).
        """
        page, total = self.page(shoot_id, limit, offset, sort, descending, filters)
        totals: dict[str, float] = {}
        for row in page:
            for joint, share in (row["joint_violations"] or {}).items():
                totals[joint] = totals.get(joint, 0.0) + float(share)
        joints = sorted(totals, key=lambda j: (-totals[j], j))
        values = [
            [
                (row["joint_violations"] or {}).get(joint, 0.0)
                if row["violation_share"] is not None
                else None
                for row in page
            ]
            for joint in joints
        ]
        return {
            "joints": joints,
            "takes": [
                {"take_id": r["take_id"], "name": r["name"], "score": r["score"]} for r in page
            ],
            "values": values,
            "total": total,
        }

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
        order = (take_qa.c.score.asc().nulls_last(), take_qa.c.name, take_qa.c.take_id)
        query = (
            select(take_qa, takes.c.format, takes.c.fps, takes.c.n_joints)
            .join(takes, takes.c.id == take_qa.c.take_id)
            .order_by(*order)
            .limit(1)
        )
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
            found = None
            if skipped is not None:
                later = conn.execute(query.where(where, _after_in_order(skipped))).mappings()
                found = later.first()
                if found is None:  # past the last: round to the first that is not it
                    first = query.where(where, take_qa.c.take_id != after)
                    found = conn.execute(first).mappings().first()
            else:
                found = conn.execute(query.where(where)).mappings().first()
        return (plain(found) if found is not None else None), remaining

    # batches ---------------------------------------------------------------------------
    def finished(self, sha256s: list[str], options: dict[str, Any]) -> dict[str, str]:
        """Of these contents, those with a done run of these options and this version.

        Returns
        -------
        dict
            sha256 → take id of the finished run.
        """
        found: dict[str, str] = {}
        with self.engine.connect() as conn:
            for start in range(0, len(sha256s), 500):
                chunk = sha256s[start : start + 500]
                query = select(runs.c.input_sha256, runs.c.take_id, runs.c.options).where(
                    runs.c.input_sha256.in_(chunk),
                    runs.c.status == "done",
                    runs.c.version == __version__,
                )
                for row in conn.execute(query).mappings():
                    if row["options"] == options:
                        found[str(row["input_sha256"])] = str(row["take_id"])
        return found

    def record_done(self, done: list[DoneTake]) -> None:
        """Store takes analysed elsewhere, each with its one done run, in one transaction.

        Each take is new (a batch made its id), so its ``take_qa`` row is built from the
        values at hand (its only run, no review) instead of read back per take; the three
        tables get one multi-row insert each, a few statements for any number of takes.
        """
        if not done:
            return
        now = utc_now()
        take_rows, run_rows, qa_rows = [], [], []
        for item in done:
            take = {**item.take, "created_at": now}
            run = {
                "id": item.run_id,
                "take_id": take["id"],
                "status": "done",
                "progress": 100,
                "step": "done",
                "options": item.options,
                "input_sha256": take["sha256"],
                "version": __version__,
                "summary": item.summary,
                "server_time_s": item.server_time_s,
                "created_at": now,
                "started_at": now,
                "finished_at": now,
            }
            take_rows.append(take)
            run_rows.append(run)
            qa_rows.append(
                {
                    "take_id": take["id"],
                    "shoot_id": take.get("shoot_id"),
                    "name": take["name"],
                    "kind": take["kind"],
                    "created_at": now,
                    "run_id": item.run_id,
                    "status": "done",
                    "review_status": "unreviewed",
                    "reviewer": None,
                    **qa_values(take, run),
                }
            )
        with self.engine.begin() as conn:
            conn.execute(insert(takes), take_rows)
            conn.execute(insert(runs), run_rows)
            conn.execute(insert(take_qa), qa_rows)

    def known_hashes(self, paths: list[str]) -> dict[str, tuple[int, int, str]]:
        """Cached ``(size, mtime_ns, sha256)`` of these source paths."""
        found: dict[str, tuple[int, int, str]] = {}
        with self.engine.connect() as conn:
            for start in range(0, len(paths), 500):
                query = select(source_hashes).where(
                    source_hashes.c.path.in_(paths[start : start + 500])
                )
                for row in conn.execute(query).mappings():
                    found[str(row["path"])] = (
                        int(row["size_bytes"]),
                        int(row["mtime_ns"]),
                        str(row["sha256"]),
                    )
        return found

    def remember_hashes(self, rows: list[dict[str, Any]]) -> None:
        """Store ``{"path", "size_bytes", "mtime_ns", "sha256"}`` rows, replacing older ones."""
        if not rows:
            return
        with self.engine.begin() as conn:
            for start in range(0, len(rows), 500):
                chunk = rows[start : start + 500]
                conn.execute(
                    delete(source_hashes).where(
                        source_hashes.c.path.in_([r["path"] for r in chunk])
                    )
                )
                conn.execute(insert(source_hashes), chunk)

    def qa_rows(self, take_ids: list[str]) -> dict[str, dict[str, Any]]:
        """The summary rows of these takes, by take id."""
        found: dict[str, dict[str, Any]] = {}
        with self.engine.connect() as conn:
            for start in range(0, len(take_ids), 500):
                chunk = take_ids[start : start + 500]
                query = select(take_qa).where(take_qa.c.take_id.in_(chunk))
                for row in conn.execute(query).mappings():
                    found[str(row["take_id"])] = plain(row)
        return found

    def assign(self, take_id: str, shoot_id: str | None) -> None:
        """Move a take into a shoot (or out of any, with None)."""
        with self.engine.begin() as conn:
            conn.execute(update(takes).where(takes.c.id == take_id).values(shoot_id=shoot_id))
            sync_take(conn, take_id)

    def progress(self, shoot_id: str) -> dict[str, Any]:
        """Counts per status and frames analysed, for a running import or batch."""
        shoot = self.get(shoot_id)
        with self.engine.connect() as conn:
            frames_done = conn.execute(
                select(func.coalesce(func.sum(take_qa.c.n_frames), 0)).where(
                    take_qa.c.shoot_id == shoot_id, take_qa.c.status == "done"
                )
            ).scalar_one()
        counts = shoot["status_counts"]
        return {
            "shoot_id": shoot_id,
            "n_takes": shoot["n_takes"],
            "status_counts": counts,
            "frames_done": int(frames_done),
            # From the same counts (one query), so "finished" never contradicts them.
            "finished": counts["queued"] + counts["running"] == 0,
        }


def _same_name(
    conn: Connection, clean: str, other_than: str | None = None
) -> tuple[str, str] | None:
    """``(id, name)`` of a shoot whose name equals ``clean`` but for case ("Day 1" and
    "day 1"), other than shoot ``other_than``; None when there is none.

    Compared in Python (``str.casefold``), not with SQL ``lower``, which SQLite applies to
    ASCII letters only; shoots are few enough to list.
    """
    key = clean.casefold()
    for shoot_id, stored in conn.execute(select(shoots.c.id, shoots.c.name)):
        if stored.casefold() == key and shoot_id != other_than:
            return str(shoot_id), str(stored)
    return None


def _refuse_taken(conn: Connection, clean: str, other_than: str | None = None) -> None:
    """:class:`ConflictError` when another shoot has the name, up to case: two shoots whose
    names differ only in case read as one in the shoot list and the review history."""
    found = _same_name(conn, clean, other_than)
    if found is not None:
        raise ConflictError(
            f"Expected a new shoot name, got {clean!r}, which exists as {found[1]!r}"
        )


def _checked_name(name: str) -> str:
    """The name without control and format characters (as take names, ``display_name``),
    its runs of white space made one space, in Unicode's composed form (NFC), so that "Ünï"
    typed on two systems is one name, not two shoots that look alike."""
    text = unicodedata.normalize("NFC", str(name))
    clean = " ".join(display_name(text, max_length=len(text)).split())
    if not clean or len(clean) > 255:
        raise InputError(f"Expected a shoot name of 1–255 characters, got {name!r}")
    return clean
