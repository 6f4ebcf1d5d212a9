"""Shoots: named collections of takes; their rows, names, counts, limits model and progress.

:class:`ShootStore` is the shoot store whole: this module's records of shoots, with the take
table's pages (``store/shoot_pages.py``), the heat map (``store/shoot_heatmap.py``), the review
queue (``store/review_queue.py``) and a batch's reads and writes (``store/batch_cache.py``).
Reads go to the ``take_qa`` rows (one per take, kept in step by the store), so a shoot's table
sorts and filters on indexed columns without walking every run.
"""

from __future__ import annotations

import unicodedata
from typing import Any

from sqlalchemy import Connection, delete, func, insert, select, update
from sqlalchemy.exc import IntegrityError

from mocapqa.core.text import display_name
from mocapqa.errors import ConflictError, InputError, NotFoundError
from mocapqa.store.batch_cache import BatchCache
from mocapqa.store.limits_runs import run_limits_model, shoot_limits_model, stale_limits_counts
from mocapqa.store.qa import sync_take
from mocapqa.store.repository import RUN_STATUSES
from mocapqa.store.review_queue import ReviewQueue
from mocapqa.store.rows import read_rows
from mocapqa.store.shoot_heatmap import ShootHeatmap
from mocapqa.store.shoot_pages import SORT_COLUMNS, TakeFilter
from mocapqa.store.stamps import new_id, utc_now
from mocapqa.store.tables import reviews, runs, shoots, take_qa, takes
from mocapqa.store.take_writer import DoneTake

__all__ = [
    "SORT_COLUMNS",  # of store/shoot_pages.py, imported from here by the API
    "DoneTake",  # of store/take_writer.py, imported from here by the batch
    "ShootStore",
    "TakeFilter",  # of store/shoot_pages.py, imported from here by the API
]


class ShootStore(ShootHeatmap, ReviewQueue, BatchCache):
    """Database access for shoots and their take tables.

    Parameters
    ----------
    engine : Engine
        The repository's engine (its schema already created).
    """

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
            return shoot_limits_model(conn, shoot_id)

    def run_limits_model(self, requested: str | None, shoot_id: str | None) -> str:
        """The limits model a new run of a take of shoot ``shoot_id`` (None: of none) checks
        with (:func:`~mocapqa.store.limits_runs.run_limits_model`)."""
        with self.engine.connect() as conn:
            return run_limits_model(conn, requested, shoot_id)

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
            rows = read_rows(conn, query)
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
