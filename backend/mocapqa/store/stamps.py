"""Ids and times the store gives new rows: 32-character hex ids, aware UTC times."""

from __future__ import annotations

import uuid
from datetime import UTC, datetime

__all__ = ["new_id", "utc_now"]


def new_id() -> str:
    """A new 32-character hex id."""
    return uuid.uuid4().hex


def utc_now() -> datetime:
    """The current time, UTC."""
    return datetime.now(UTC)
