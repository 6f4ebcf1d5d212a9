"""When each credential was last used, recorded without a write per request.

Checking a token is a read. Writing ``tokens.last_used_at`` on every request made every read a
write: on SQLite, 40 parallel requests of one viewer queued behind one write lock (9 of 40
answered 500 "database is locked" after the busy timeout). A :class:`LastUse` notes a use in
memory, at most once per :data:`RECORD_EVERY_S` per credential, and a daemon thread writes the
noted times in one transaction, off the request path. ``last_used_at`` is therefore accurate to
that interval (plus the writer's delay), which is what a "last used" column in a token list is
read for; a use is never lost while the server runs, and :meth:`LastUse.flush` writes what is
noted when it stops.
"""

from __future__ import annotations

import logging
import threading
import time
from datetime import datetime

from sqlalchemy import Engine, or_, update
from sqlalchemy.exc import SQLAlchemyError

from mocapqa.store.tables import tokens

__all__ = ["RECORD_EVERY_S", "LastUse"]

log = logging.getLogger(__name__)

RECORD_EVERY_S = 60.0
"""Least time between two recorded uses of one credential, seconds."""
_WRITE_DELAY_S = 1.0
"""How long the writer waits after a note, so that uses noted together are written together."""
_IDLE_EXIT_S = 30.0
"""How long the writer thread waits for a note before it ends."""
_FORGET_AFTER = 10_000
"""Credentials remembered before those older than :data:`RECORD_EVERY_S` are forgotten."""


class LastUse:
    """Coalesced ``last_used_at`` writes for one database.

    Parameters
    ----------
    engine : Engine
        The database the ``tokens`` table lives in.
    every_s : float
        Least time between two recorded uses of one credential, seconds.
    """

    def __init__(self, engine: Engine, every_s: float = RECORD_EVERY_S) -> None:
        self.engine = engine
        self.every_s = every_s
        self._lock = threading.Lock()
        self._noted: dict[str, float] = {}  # credential id -> monotonic time last noted
        self._pending: dict[str, datetime] = {}  # credential id -> use time to write
        self._wake = threading.Event()
        self._writer: threading.Thread | None = None

    def note(self, token_id: str, at: datetime) -> None:
        """Note that credential ``token_id`` was used at ``at`` (UTC); costs no query."""
        now = time.monotonic()
        with self._lock:
            last = self._noted.get(token_id)
            if last is not None and now - last < self.every_s:
                return
            if len(self._noted) >= _FORGET_AFTER:
                self._noted = {k: t for k, t in self._noted.items() if now - t < self.every_s}
            self._noted[token_id] = now
            self._pending[token_id] = at
            if self._writer is None or not self._writer.is_alive():
                self._writer = threading.Thread(
                    target=self._run, name="mocapqa-last-use", daemon=True
                )
                self._writer.start()
        self._wake.set()

    def pending(self) -> int:
        """How many noted uses are not yet written."""
        with self._lock:
            return len(self._pending)

    def flush(self) -> None:
        """Write every noted use now (one transaction); a failed write is kept for the next."""
        with self._lock:
            batch, self._pending = self._pending, {}
        if not batch:
            return
        try:
            with self.engine.begin() as conn:
                for token_id, at in batch.items():
                    conn.execute(
                        update(tokens)
                        .where(
                            tokens.c.id == token_id,
                            or_(tokens.c.last_used_at.is_(None), tokens.c.last_used_at < at),
                        )
                        .values(last_used_at=at)
                    )
        except SQLAlchemyError as e:  # kept and retried: a busy database is not a lost use
            log.warning("last use of %d credential(s) not written yet: %s", len(batch), e)
            with self._lock:
                for token_id, at in batch.items():
                    self._pending.setdefault(token_id, at)
            self._wake.set()

    def _run(self) -> None:
        while True:
            if not self._wake.wait(timeout=_IDLE_EXIT_S):
                with self._lock:  # idle: the thread ends; the next note starts another
                    if not self._pending:
                        self._writer = None
                        return
                continue
            self._wake.clear()
            time.sleep(_WRITE_DELAY_S)
            self.flush()
