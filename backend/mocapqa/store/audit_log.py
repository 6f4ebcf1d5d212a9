"""The audit log: append-only, who did what, when and from where (no API route edits it)."""

from __future__ import annotations

from typing import Any, Protocol

from sqlalchemy import func, insert, select

from mocapqa.core.text import display_name
from mocapqa.store.access import TableAccess
from mocapqa.store.rows import read_rows
from mocapqa.store.stamps import utc_now
from mocapqa.store.tables import audit

__all__ = ["Actor", "AuditLog"]


class Actor(Protocol):
    """Who did it: a user's id and name (:class:`~mocapqa.store.accounts.User`)."""

    @property
    def id(self) -> int: ...

    @property
    def name(self) -> str: ...


class AuditLog(TableAccess):
    """Reads and writes of :data:`~mocapqa.store.tables.audit` (a part of
    :class:`~mocapqa.store.accounts.Accounts`)."""

    def record(
        self,
        action: str,
        user: Actor | None,
        client: str,
        target: str = "",
        detail: str = "",
    ) -> None:
        """Append an audit entry (who, now, what, from where).

        Client-given text (a file name, a note) is stored as the API echoes it, without control
        or format characters: PostgreSQL refuses NUL in text, and the log is read by people.
        """
        target, detail = display_name(target, 255), display_name(detail, 2000)
        with self.engine.begin() as conn:
            conn.execute(
                insert(audit).values(
                    at=utc_now(),
                    user_id=user.id if user else None,
                    user_name=user.name if user else None,
                    action=action[:32],
                    target=target,
                    detail=detail,
                    client=client[:64],
                )
            )

    def list_audit(self, limit: int, offset: int) -> tuple[list[dict[str, Any]], int]:
        """A page of audit entries, newest first, and their total."""
        with self.engine.connect() as conn:
            total = int(conn.execute(select(func.count()).select_from(audit)).scalar_one())
            items = read_rows(
                conn, select(audit).order_by(audit.c.id.desc()).limit(limit).offset(offset)
            )
        return items, total
