"""Opening a database: the engine, its connection pool and SQLite's pragmas."""

from __future__ import annotations

import sqlite3
import time
from typing import Any

from sqlalchemy import Engine, create_engine, event

__all__ = ["SPARE_CONNECTIONS", "SQLITE_BUSY_MS", "open_engine"]

SQLITE_BUSY_MS = 10_000
"""How long a SQLite connection waits for another's write lock before "database is locked"."""
SPARE_CONNECTIONS = 5
"""Connections beyond one per thread: a thread may hold a second for a nested read."""


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


def open_engine(database_url: str, threads: int) -> Engine:
    """An engine on ``database_url`` whose pool suits ``threads`` threads.

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
    sqlite = database_url.startswith("sqlite")
    engine = create_engine(
        database_url,
        # A SQLite file cannot drop a connection as a server can: no ping per checkout.
        pool_pre_ping=not sqlite,
        pool_size=threads + SPARE_CONNECTIONS,
        max_overflow=SPARE_CONNECTIONS,
    )
    if engine.dialect.name == "sqlite":
        event.listen(engine, "connect", _sqlite_pragmas)
    return engine
