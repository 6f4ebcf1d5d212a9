"""The repository: every read and write of takes, runs and reviews goes through here.

New takes and runs are written by the store's one writer (``store/take_writer.py``), takes are
listed from their ``take_qa`` rows (``store/take_listing.py``). Rows come back as plain dicts
(JSON-ready apart from datetimes). A run's life is ``queued → running → done | failed``;
:meth:`Repository.recover_interrupted` puts runs that a stopped server left queued or running
back in the queue (their outputs are only published after they are complete, so nothing
half-written is ever marked done).
"""

from __future__ import annotations

import logging
from typing import Any, Literal, get_args

from sqlalchemy import (
    Engine,
    delete,
    func,
    insert,
    select,
    update,
)
from sqlalchemy.exc import IntegrityError

from mocapqa.core.text import display_name
from mocapqa.errors import ConflictError, InputError, NotFoundError
from mocapqa.store.connect import open_engine
from mocapqa.store.qa import lock_take, sync_take
from mocapqa.store.rows import plain, read_rows
from mocapqa.store.stamps import new_id, utc_now
from mocapqa.store.tables import reviews, runs, take_qa, takes
from mocapqa.store.take_listing import REVIEW_STATUS, TAKE_ROWS, checked_choice
from mocapqa.store.take_writer import add_run, queued_run, write_takes
from mocapqa.store.upgrade import upgrade_database

__all__ = [
    "REVIEW_STATUSES",
    "RUN_STATUSES",
    "Repository",
    "ReviewStatus",
    "RunStatus",
    "new_id",  # of store/stamps.py, still imported from here outside the store
    "utc_now",
]

log = logging.getLogger(__name__)

RunStatus = Literal["queued", "running", "done", "failed"]
"""A run's state (an enum in the OpenAPI, also of the take tables' ``status`` filter)."""
RUN_STATUSES: tuple[RunStatus, ...] = get_args(RunStatus)
"""A run's states, in life order."""
ReviewStatus = Literal["unreviewed", "approved", "needs_fix", "rejected"]
"""A take's review decision."""
REVIEW_STATUSES: tuple[ReviewStatus, ...] = get_args(ReviewStatus)
"""The review decisions a take can have."""


class Repository:
    """Database access for takes, runs and reviews.

    Parameters
    ----------
    database_url, threads
        The database and the threads that use it at once
        (:func:`~mocapqa.store.connect.open_engine`).
    """

    def __init__(self, database_url: str, threads: int = 10) -> None:
        self.database_url = database_url
        self.engine: Engine = open_engine(database_url, threads)
        self.upgrades = upgrade_database(self.engine)
        """What opening the database did to its schema (empty when it was up to date)."""
        for step in self.upgrades:
            log.info("database: %s", step)

    def ping(self) -> None:
        """Run a trivial query (for health checks); raises when the database is unreachable."""
        with self.engine.connect() as conn:
            conn.execute(select(1))

    def close(self) -> None:
        """Release the connection pool."""
        self.engine.dispose()

    # takes -----------------------------------------------------------------------------
    def add_take(self, values: dict[str, Any], options: dict[str, Any]) -> tuple[str, str]:
        """Insert a take and its first (queued) run in one transaction.

        Returns
        -------
        take_id, run_id : str

        Raises
        ------
        NotFoundError
            When ``values`` names a shoot that no longer exists (deleted during an import).
        """
        take_id = str(values.get("id") or new_id())
        take = {**values, "id": take_id}
        now = utc_now()
        try:
            with self.engine.begin() as conn:
                run = queued_run(conn, take, new_id(), options, now)
                write_takes(conn, [(take, run)], now)
        except IntegrityError as e:
            shoot_id = values.get("shoot_id")
            if shoot_id is not None:
                # The shoot was deleted while its import ran.
                raise NotFoundError(f"Expected shoot {shoot_id!r} to exist, got none") from e
            raise
        return take_id, str(run["id"])

    def same_content(self, take_id: str) -> str | None:
        """The name of another take of the same shoot with byte-identical content (the same
        file imported twice), or None (also for a take outside a shoot)."""
        with self.engine.connect() as conn:
            row = conn.execute(
                select(takes.c.shoot_id, takes.c.sha256).where(takes.c.id == take_id)
            ).first()
            if row is None or row[0] is None:
                return None
            other = conn.execute(
                select(takes.c.name)
                .where(takes.c.shoot_id == row[0], takes.c.sha256 == row[1], takes.c.id != take_id)
                .order_by(takes.c.created_at)
                .limit(1)
            ).scalar()
        return None if other is None else str(other)

    def get_take(self, take_id: str) -> dict[str, Any]:
        """One take with its latest run and review fields.

        Raises
        ------
        NotFoundError
        """
        with self.engine.connect() as conn:
            found = read_rows(conn, TAKE_ROWS.where(takes.c.id == take_id))
        if not found:
            raise NotFoundError(f"Expected take {take_id!r} to exist, got none")
        return found[0]

    def list_takes(
        self,
        limit: int = 50,
        offset: int = 0,
        status: str | None = None,
        review_status: str | None = None,
    ) -> tuple[list[dict[str, Any]], int]:
        """A page of takes, newest first, and the total count after filtering."""
        chosen = (
            (take_qa.c.status, checked_choice("status", status, RUN_STATUSES)),
            (REVIEW_STATUS, checked_choice("review_status", review_status, REVIEW_STATUSES)),
        )
        clauses = [column == value for column, value in chosen if value is not None]
        page = (
            TAKE_ROWS.where(*clauses)
            .order_by(takes.c.created_at.desc(), takes.c.id)
            .limit(limit)
            .offset(offset)
        )
        with self.engine.connect() as conn:
            rows = read_rows(conn, page)
            total = conn.execute(
                select(func.count())
                .select_from(takes.outerjoin(take_qa, take_qa.c.take_id == takes.c.id))
                .where(*clauses)
            ).scalar_one()
        return rows, int(total)

    def set_owner(self, take_id: str, owner_id: int | None) -> None:
        """Record who uploaded a take (none while the server has no users)."""
        with self.engine.begin() as conn:
            conn.execute(update(takes).where(takes.c.id == take_id).values(owner_id=owner_id))

    def delete_take(self, take_id: str) -> list[str]:
        """Delete a take with its runs and reviews; returns the deleted run ids."""
        with self.engine.begin() as conn:
            found = lock_take(conn, take_id)
            if found is None:
                raise NotFoundError(f"Expected take {take_id!r} to exist, got none")
            run_ids = [
                str(r)
                for r in conn.execute(select(runs.c.id).where(runs.c.take_id == take_id)).scalars()
            ]
            conn.execute(delete(take_qa).where(take_qa.c.take_id == take_id))
            conn.execute(delete(reviews).where(reviews.c.take_id == take_id))
            conn.execute(delete(runs).where(runs.c.take_id == take_id))
            conn.execute(delete(takes).where(takes.c.id == take_id))
        return run_ids

    # runs ------------------------------------------------------------------------------
    def add_run(self, take_id: str, options: dict[str, Any]) -> str:
        """Queue a new run of a take with the given options; earlier runs are kept."""
        take = self.get_take(take_id)
        run_id = new_id()
        gone = NotFoundError(f"Expected take {take_id!r} to exist, got none (deleted meanwhile)")
        try:
            with self.engine.begin() as conn:
                if lock_take(conn, take_id) is None:
                    raise gone
                add_run(conn, take, run_id, options, utc_now())
        except IntegrityError as error:  # the take's foreign key: deleted after the lock read
            raise gone from error
        return run_id

    def get_run(self, run_id: str) -> dict[str, Any]:
        """One run.

        Raises
        ------
        NotFoundError
        """
        with self.engine.connect() as conn:
            row = conn.execute(select(runs).where(runs.c.id == run_id)).mappings().first()
        if row is None:
            raise NotFoundError(f"Expected run {run_id!r} to exist, got none")
        return plain(row)

    def list_runs(self, take_id: str) -> list[dict[str, Any]]:
        """All runs of a take, oldest first."""
        with self.engine.connect() as conn:
            return read_rows(
                conn, select(runs).where(runs.c.take_id == take_id).order_by(runs.c.created_at)
            )

    def require_done(self, run_id: str) -> dict[str, Any]:
        """The run, if it finished; :class:`ConflictError` otherwise."""
        run = self.get_run(run_id)
        if run["status"] != "done":
            raise ConflictError(f"Expected run {run_id} to be done, got {run['status']!r}")
        return run

    def mark_running(self, run_id: str) -> None:
        """Move a run from queued to running."""
        self._change_run(
            run_id,
            status="running",
            progress=1,
            step="starting",
            started_at=utc_now(),
            attempts=runs.c.attempts + 1,
        )

    def set_progress(self, run_id: str, percent: int, step: str) -> None:
        """Record a running run's progress (0–100) and current step."""
        with self.engine.begin() as conn:
            conn.execute(
                update(runs)
                .where(runs.c.id == run_id)
                .values(progress=max(0, min(100, int(percent))), step=step[:255])
            )

    def finish_run(
        self,
        run_id: str,
        summary: dict[str, Any] | None,
        error: str | None,
        server_time_s: float,
    ) -> None:
        """Mark a run done (``error`` None) or failed."""
        self._change_run(
            run_id,
            status="failed" if error else "done",
            progress=100,
            step="failed" if error else "done",
            error=error,
            summary=summary,
            server_time_s=server_time_s,
            finished_at=utc_now(),
        )

    def _change_run(self, run_id: str, **values: Any) -> None:
        """Set a run's ``values`` and rebuild its take's ``take_qa`` row, in one transaction
        (the take locked first, :func:`~mocapqa.store.qa.lock_take`)."""
        with self.engine.begin() as conn:
            found = conn.execute(select(runs.c.take_id).where(runs.c.id == run_id)).scalar()
            take_id = None if found is None else str(found)
            if take_id is not None:
                lock_take(conn, take_id)
            conn.execute(update(runs).where(runs.c.id == run_id).values(**values))
            if take_id is not None:
                sync_take(conn, take_id)

    def recover_interrupted(self, max_attempts: int = 2) -> list[str]:
        """Re-queue the runs a stopped server left queued or running; returns their ids.

        A run already started ``max_attempts`` times is failed with the reason instead (the
        take may be what stops the server).
        """
        with self.engine.begin() as conn:
            rows = conn.execute(
                select(runs.c.id, runs.c.attempts)
                .where(runs.c.status.in_(("queued", "running")))
                .order_by(runs.c.created_at)
            ).all()
            ids = [str(r.id) for r in rows if int(r.attempts or 0) < max_attempts]
            exhausted = [str(r.id) for r in rows if int(r.attempts or 0) >= max_attempts]
            if ids:
                conn.execute(
                    update(runs)
                    .where(runs.c.id.in_(ids))
                    .values(status="queued", progress=0, step="re-queued after a restart")
                )
            if exhausted:
                conn.execute(
                    update(runs)
                    .where(runs.c.id.in_(exhausted))
                    .values(
                        status="failed",
                        progress=100,
                        step="failed",
                        error=(
                            f"Expected the run to finish, got the server stopped during it "
                            f"{max_attempts} times; not started again"
                        ),
                        finished_at=utc_now(),
                    )
                )
            for take_id in set(
                conn.execute(select(runs.c.take_id).where(runs.c.id.in_(ids + exhausted))).scalars()
            ):
                sync_take(conn, str(take_id))
        return ids

    # reviews ---------------------------------------------------------------------------
    def add_review(
        self, take_id: str, status: str, notes: str, reviewer: str, user_id: int | None = None
    ) -> dict[str, Any]:
        """Append a review entry to a take's history, by the user ``reviewer`` (``user_id``)."""
        if status not in REVIEW_STATUSES:
            raise InputError(f"Expected review status in {list(REVIEW_STATUSES)}, got {status!r}")
        self.get_take(take_id)
        gone = NotFoundError(f"Expected take {take_id!r} to exist, got none (deleted meanwhile)")
        try:
            return self._insert_review(take_id, status, notes, reviewer, user_id, gone)
        except IntegrityError as error:  # the take's foreign key: deleted after the lock read
            raise gone from error

    def _insert_review(
        self,
        take_id: str,
        status: str,
        notes: str,
        reviewer: str,
        user_id: int | None,
        gone: NotFoundError,
    ) -> dict[str, Any]:
        """Insert one review row and rebuild the take's QA row, in one transaction."""
        with self.engine.begin() as conn:
            if lock_take(conn, take_id) is None:
                raise gone
            result = conn.execute(
                insert(reviews)
                .values(
                    take_id=take_id,
                    status=status,
                    notes=notes.replace("\x00", ""),
                    reviewer=display_name(reviewer) or "anonymous",
                    user_id=user_id,
                    created_at=utc_now(),
                )
                .returning(reviews)
            )
            row = plain(result.mappings().one())
            sync_take(conn, take_id)
            return row

    def list_reviews(self, take_id: str) -> list[dict[str, Any]]:
        """A take's review history, newest first."""
        self.get_take(take_id)
        with self.engine.connect() as conn:
            return read_rows(
                conn,
                select(reviews).where(reviews.c.take_id == take_id).order_by(reviews.c.id.desc()),
            )
