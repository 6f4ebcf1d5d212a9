"""Rows as the store hands them out: plain dicts whose times are aware and in UTC.

Every time the store writes is UTC. PostgreSQL's ``timestamptz`` hands them back aware; SQLite
stores no zone and hands them back naive, so each read passes through :func:`read_rows` (a
query's rows), :func:`plain` (a whole row) or :func:`utc` (one value). The one place where that
is fixed, for every table.
"""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any, TypeVar

from sqlalchemy import Select
from sqlalchemy.engine import Connection

__all__ = ["plain", "read_rows", "utc"]

T = TypeVar("T")


def utc(value: T) -> T:
    """``value`` with UTC as its zone when it is a naive datetime; anything else as it is."""
    if isinstance(value, datetime) and value.tzinfo is None:
        return value.replace(tzinfo=UTC)  # type: ignore[return-value]
    return value


def plain(mapping: Any) -> dict[str, Any]:
    """A database row (a mapping) as a dict, its datetimes in UTC (:func:`utc`)."""
    return {key: utc(value) for key, value in dict(mapping).items()}


def read_rows(conn: Connection, query: Select[Any]) -> list[dict[str, Any]]:
    """The rows of ``query``, each through :func:`plain`."""
    return [plain(row) for row in conn.execute(query).mappings()]
