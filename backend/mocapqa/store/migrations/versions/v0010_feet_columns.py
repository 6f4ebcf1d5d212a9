"""Take rows get the feet figures of their latest run: skate, penetration and floating counts
and the largest skate with its unit.

Revision ID: 0010
Revises: 0009
Created: 2026-12-05

The counts of runs made since the feet step are in their summaries already, so each take's row
takes them from its latest done run here (as the store would when it rebuilds the row). The
largest skate was not in those summaries: it stays empty (null) until the take is analysed
again, as do all five for runs made before the feet step.
"""

from __future__ import annotations

from typing import Any

import sqlalchemy as sa
from alembic import op

revision = "0010"
down_revision = "0009"
branch_labels = None
depends_on = None

COLUMNS: dict[str, sa.types.TypeEngine[Any]] = {
    "foot_skates": sa.Integer(),
    "foot_worst_skate": sa.Float(),
    "foot_skate_unit": sa.String(16),
    "foot_penetrations": sa.Integer(),
    "foot_floating": sa.Integer(),
}
"""The new columns of ``take_qa`` and their types (copied from a run's ``summary["qa"]``)."""


def _filled_rows() -> list[dict[str, Any]]:
    """Each take row's new values (``new_<column>``) from its latest run's summary, for the
    rows that get any."""
    take_qa = sa.table("take_qa", sa.column("take_id", sa.String), sa.column("run_id", sa.String))
    runs = sa.table(
        "runs", sa.column("id", sa.String), sa.column("status"), sa.column("summary", sa.JSON)
    )
    found = op.get_bind().execute(
        sa.select(take_qa.c.take_id, runs.c.summary)
        .join(runs, runs.c.id == take_qa.c.run_id)
        .where(runs.c.status == "done")
    )
    filled = []
    for take_id, summary in found:
        qa = summary.get("qa") if isinstance(summary, dict) else None
        values = {f"new_{k}": qa.get(k) for k in COLUMNS} if isinstance(qa, dict) else {}
        if any(v is not None for v in values.values()):
            filled.append({"row_take_id": take_id, **values})
    return filled


def upgrade() -> None:
    with op.batch_alter_table("take_qa") as batch:
        for name, kind in COLUMNS.items():
            batch.add_column(sa.Column(name, kind, nullable=True))
    filled = _filled_rows()
    if filled:
        take_qa = sa.table(
            "take_qa",
            sa.column("take_id", sa.String),
            *(sa.column(k, t) for k, t in COLUMNS.items()),
        )
        op.get_bind().execute(
            sa.update(take_qa)
            .where(take_qa.c.take_id == sa.bindparam("row_take_id"))
            .values({k: sa.bindparam(f"new_{k}") for k in COLUMNS}),
            filled,
        )


def downgrade() -> None:
    with op.batch_alter_table("take_qa") as batch:
        for name in reversed(COLUMNS):
            batch.drop_column(name)
