"""The repository: every read and write of takes, runs and reviews goes through here.

Rows come back as plain dicts (JSON-ready apart from datetimes). A run's life is
``queued → running → done | failed``; :meth:`Repository.recover_interrupted` puts runs that a
stopped server left queued or running back in the queue (their outputs are only published
after they are complete, so nothing half-written is ever marked done).
"""

from __future__ import annotations

import logging
import sqlite3
import time
import uuid
from datetime import UTC, datetime
from typing import Any, Literal, get_args

from sqlalchemy import (
    Engine,
    create_engine,
    delete,
    event,
    func,
    insert,
    select,
    update,
)
from sqlalchemy.engine import Connection
from sqlalchemy.exc import IntegrityError
from sqlalchemy.sql.elements import ColumnElement

from mocapqa import __version__
from mocapqa.core.text import display_name
from mocapqa.errors import ConflictError, InputError, NotFoundError
from mocapqa.store.qa import lock_take, sync_take
from mocapqa.store.rows import plain
from mocapqa.store.tables import reviews, runs, shoots, take_qa, takes
from mocapqa.store.upgrade import upgrade_database

__all__ = [
    "REVIEW_STATUSES",
    "RUN_STATUSES",
    "Repository",
    "ReviewStatus",
    "RunStatus",
    "new_id",
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


SQLITE_BUSY_MS = 10_000
"""How long a SQLite connection waits for another's write lock before "database is locked"."""
SPARE_CONNECTIONS = 5
"""Connections beyond one per thread: a thread may hold a second for a nested read."""


_REVIEW_STATUS = func.coalesce(take_qa.c.review_status, "unreviewed")
_TAKE_ROWS = (
    select(
        takes,
        take_qa.c.run_id.label("latest_run_id"),
        take_qa.c.status,
        runs.c.summary,
        _REVIEW_STATUS.label("review_status"),
    )
    .outerjoin(take_qa, take_qa.c.take_id == takes.c.id)
    .outerjoin(runs, runs.c.id == take_qa.c.run_id)
)
"""A take with its latest run and review: read from its ``take_qa`` row (kept in step with
every write, ``store/qa.py``), built once (making the statement cost more than running it)."""


def new_id() -> str:
    """A new 32-character hex id."""
    return uuid.uuid4().hex


def utc_now() -> datetime:
    """The current time, UTC."""
    return datetime.now(UTC)


def _sqlite_pragmas(dbapi_connection: Any, connection_record: Any) -> None:
    del connection_record
    cursor = dbapi_connection.cursor()
    cursor.execute(f"PRAGMA busy_timeout={SQLITE_BUSY_MS}")
    cursor.execute("PRAGMA foreign_keys=ON")
    _switch_to_wal(cursor)
    cursor.close()


def _switch_to_wal(cursor: Any) -> None:
    """Put the database in WAL mode (kept in the file: once is enough). Switching needs the
    file alone, and SQLite answers "database is locked" at once, without its busy wait, when
    another connection opening the same new file is switching or migrating it: tried again
    for up to :data:`SQLITE_BUSY_MS`."""
    deadline = time.monotonic() + SQLITE_BUSY_MS / 1000
    while True:
        try:
            mode = cursor.execute("PRAGMA journal_mode").fetchone()[0]
            if str(mode).lower() != "wal":
                cursor.execute("PRAGMA journal_mode=WAL")
            return
        except sqlite3.OperationalError as e:
            if "locked" not in str(e) or time.monotonic() > deadline:
                raise
            time.sleep(0.01)


class Repository:
    """Database access for takes, runs and reviews.

    Parameters
    ----------
    database_url : str
        SQLAlchemy URL (``sqlite:///...`` or ``postgresql+psycopg://...``).
    threads : int
        Threads that use the database at once (a server's request threads and job workers).
        The pool keeps that many connections and :data:`SPARE_CONNECTIONS` more, so that no
        request waits for a connection another holds, or pays for opening one (the library's
        default of 5 kept + 10 more made 40 parallel requests queue for 30 s, and opened and
        closed a SQLite connection, with its pragmas, on most requests). Connections are
        opened when first needed.
    """

    def __init__(self, database_url: str, threads: int = 10) -> None:
        self.database_url = database_url
        sqlite = database_url.startswith("sqlite")
        self.engine: Engine = create_engine(
            database_url,
            # A SQLite file cannot drop a connection as a server can: no ping per checkout.
            pool_pre_ping=not sqlite,
            pool_size=threads + SPARE_CONNECTIONS,
            max_overflow=SPARE_CONNECTIONS,
        )
        if self.engine.dialect.name == "sqlite":
            event.listen(self.engine, "connect", _sqlite_pragmas)
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
        try:
            with self.engine.begin() as conn:
                row = {**values, "id": take_id, "created_at": utc_now()}
                conn.execute(insert(takes).values(**row))
                run_id = self._insert_run(conn, take_id, str(values["sha256"]), options)
                sync_take(conn, take_id)
        except IntegrityError as e:
            shoot_id = values.get("shoot_id")
            if shoot_id is not None:
                # The shoot was deleted while its import ran.
                raise NotFoundError(f"Expected shoot {shoot_id!r} to exist, got none") from e
            raise
        return take_id, run_id

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
        items, _ = self._query_takes(take_id=take_id)
        if not items:
            raise NotFoundError(f"Expected take {take_id!r} to exist, got none")
        return items[0]

    def list_takes(
        self,
        limit: int = 50,
        offset: int = 0,
        status: str | None = None,
        review_status: str | None = None,
    ) -> tuple[list[dict[str, Any]], int]:
        """A page of takes, newest first, and the total count after filtering."""
        if status is not None and status not in RUN_STATUSES:
            raise InputError(f"Expected status in {list(RUN_STATUSES)}, got {status!r}")
        if review_status is not None and review_status not in REVIEW_STATUSES:
            raise InputError(
                f"Expected review_status in {list(REVIEW_STATUSES)}, got {review_status!r}"
            )
        return self._query_takes(limit, offset, status, review_status)

    def _query_takes(
        self,
        limit: int = 50,
        offset: int = 0,
        status: str | None = None,
        review_status: str | None = None,
        take_id: str | None = None,
    ) -> tuple[list[dict[str, Any]], int]:
        clauses: list[ColumnElement[bool]] = []
        if take_id is not None:
            clauses.append(takes.c.id == take_id)
        if status is not None:
            clauses.append(take_qa.c.status == status)
        if review_status is not None:
            clauses.append(_REVIEW_STATUS == review_status)  # noqa: SIM300 - an SQL expression
        page = (
            _TAKE_ROWS.where(*clauses)
            .order_by(takes.c.created_at.desc(), takes.c.id)
            .limit(limit)
            .offset(offset)
        )
        with self.engine.connect() as conn:
            rows = [plain(r) for r in conn.execute(page).mappings()]
            if take_id is not None:
                return rows, len(rows)
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
    def _insert_run(
        self, conn: Connection, take_id: str, sha256: str, options: dict[str, Any]
    ) -> str:
        if options.get("limits_model") is None:
            # Imported here: the catalog loads the limits stack, which the batch client
            # (it records runs through this store) never needs otherwise.
            from mocapqa.limits.catalog import DEFAULT_MODEL

            # A run of a take in a shoot checks limits with the shoot's model; the name is
            # recorded with the run, so its options say which model it used.
            query = (
                select(shoots.c.limits_model)
                .select_from(takes.join(shoots, takes.c.shoot_id == shoots.c.id))
                .where(takes.c.id == take_id)
            )
            chosen = conn.execute(query).scalar()
            options = {**options, "limits_model": chosen or DEFAULT_MODEL}
        run_id = new_id()
        conn.execute(
            insert(runs).values(
                id=run_id,
                take_id=take_id,
                status="queued",
                progress=0,
                step="queued",
                options=options,
                input_sha256=sha256,
                version=__version__,
                created_at=utc_now(),
            )
        )
        return run_id

    def add_run(self, take_id: str, options: dict[str, Any]) -> str:
        """Queue a new run of a take with the given options; earlier runs are kept."""
        take = self.get_take(take_id)
        with self.engine.begin() as conn:
            lock_take(conn, take_id)
            run_id = self._insert_run(conn, take_id, str(take["sha256"]), options)
            sync_take(conn, take_id)
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
            rows = conn.execute(
                select(runs).where(runs.c.take_id == take_id).order_by(runs.c.created_at)
            ).mappings()
            return [plain(r) for r in rows]

    def require_done(self, run_id: str) -> dict[str, Any]:
        """The run, if it finished; :class:`ConflictError` otherwise."""
        run = self.get_run(run_id)
        if run["status"] != "done":
            raise ConflictError(f"Expected run {run_id} to be done, got {run['status']!r}")
        return run

    def mark_running(self, run_id: str) -> None:
        """Move a run from queued to running."""
        with self.engine.begin() as conn:
            self._lock_run_take(conn, run_id)
            conn.execute(
                update(runs)
                .where(runs.c.id == run_id)
                .values(
                    status="running",
                    progress=1,
                    step="starting",
                    started_at=utc_now(),
                    attempts=runs.c.attempts + 1,
                )
            )
            self._sync_run_take(conn, run_id)

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
        with self.engine.begin() as conn:
            self._lock_run_take(conn, run_id)
            conn.execute(
                update(runs)
                .where(runs.c.id == run_id)
                .values(
                    status="failed" if error else "done",
                    progress=100,
                    step="failed" if error else "done",
                    error=error,
                    summary=summary,
                    server_time_s=server_time_s,
                    finished_at=utc_now(),
                )
            )
            self._sync_run_take(conn, run_id)

    def _lock_run_take(self, conn: Connection, run_id: str) -> None:
        take_id = conn.execute(select(runs.c.take_id).where(runs.c.id == run_id)).scalar()
        if take_id is not None:
            lock_take(conn, str(take_id))

    def _sync_run_take(self, conn: Connection, run_id: str) -> None:
        take_id = conn.execute(select(runs.c.take_id).where(runs.c.id == run_id)).scalar()
        if take_id is not None:
            sync_take(conn, str(take_id))

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
        with self.engine.begin() as conn:
            lock_take(conn, take_id)
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
            rows = conn.execute(
                select(reviews).where(reviews.c.take_id == take_id).order_by(reviews.c.id.desc())
            ).mappings()
            return [plain(r) for r in rows]
