"""Take listings, every one read from the ``take_qa`` rows (the read model: one row per take
with its latest run's status and summary and its latest review, ``store/qa.py``).

Two shapes of a listed take: :data:`TAKE_ROWS`, the take as the take list and a take's page show
it (the ``takes`` row with its latest run's id, status and summary and its review status), and
:data:`TABLE_ROWS`, a row of a shoot's take table (the ``take_qa`` row with the take's format,
rate and joint count). Rows leave through :func:`~mocapqa.store.rows.read_rows`.
"""

from __future__ import annotations

from collections.abc import Collection

from sqlalchemy import func, select

from mocapqa.errors import InputError
from mocapqa.store.tables import runs, take_qa, takes

__all__ = ["REVIEW_STATUS", "TABLE_ROWS", "TAKE_ROWS", "checked_choice"]

REVIEW_STATUS = func.coalesce(take_qa.c.review_status, "unreviewed")
"""A take's review status (unreviewed until it has one)."""

TAKE_ROWS = (
    select(
        takes,
        take_qa.c.run_id.label("latest_run_id"),
        take_qa.c.status,
        runs.c.summary,
        REVIEW_STATUS.label("review_status"),
    )
    .outerjoin(take_qa, take_qa.c.take_id == takes.c.id)
    .outerjoin(runs, runs.c.id == take_qa.c.run_id)
)
"""A take with its latest run and review, built once (making the statement cost more than
running it)."""

TABLE_ROWS = select(take_qa, takes.c.format, takes.c.fps, takes.c.n_joints).join(
    takes, takes.c.id == take_qa.c.take_id
)
"""A row of a shoot's take table: the summary columns with the take's format, rate and joint
count."""


def checked_choice(name: str, value: str | None, allowed: Collection[str]) -> str | None:
    """``value`` when it is None or one of ``allowed``.

    Raises
    ------
    InputError
        Naming the filter ``name`` and the allowed values.
    """
    if value is not None and value not in allowed:
        raise InputError(f"Expected {name} in {list(allowed)}, got {value!r}")
    return value
