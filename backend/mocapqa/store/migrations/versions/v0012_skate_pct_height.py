"""Take rows get the largest foot skate in % of the body height, the figure that compares
across takes.

Revision ID: 0012
Revises: 0011
Created: 2026-12-05

``take_qa.foot_worst_skate`` is in cm for a take whose unit converts (TRC, C3D) and in % of
the estimated body height for the others (BVH): sorted as plain numbers they mixed units.
``foot_worst_skate_pct`` is the largest skate in % of the body height for every take. A row
whose latest done run's summary has it takes it from there; a row whose largest skate is in
% height already (``foot_skate_unit`` ``"% height"``) takes that value; a row in cm from a run
made before the figure stays null (sorted last) until the take is analysed again.
"""

from __future__ import annotations

from typing import Any

import sqlalchemy as sa
from alembic import op

revision = "0012"
down_revision = "0011"
branch_labels = None
depends_on = None

COLUMN = "foot_worst_skate_pct"
"""The new column of ``take_qa`` (a run's ``summary["qa"]["foot_worst_skate_pct"]``)."""


def _share(qa: Any) -> float | None:
    """The largest skate in % of the body height of a run's QA summary, or None."""
    if not isinstance(qa, dict):
        return None
    if qa.get(COLUMN) is not None:
        return float(qa[COLUMN])
    worst = qa.get("foot_worst_skate")
    return float(worst) if worst is not None and qa.get("foot_skate_unit") == "% height" else None


def _filled_rows() -> list[dict[str, Any]]:
    """Each take row's new value (``new_value``) from its latest done run's summary, for the
    rows that get one."""
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
        share = _share(summary.get("qa") if isinstance(summary, dict) else None)
        if share is not None:
            filled.append({"row_take_id": take_id, "new_value": share})
    return filled


def upgrade() -> None:
    with op.batch_alter_table("take_qa") as batch:
        batch.add_column(sa.Column(COLUMN, sa.Float(), nullable=True))
    filled = _filled_rows()
    if filled:
        take_qa = sa.table("take_qa", sa.column("take_id", sa.String), sa.column(COLUMN, sa.Float))
        op.get_bind().execute(
            sa.update(take_qa)
            .where(take_qa.c.take_id == sa.bindparam("row_take_id"))
            .values({COLUMN: sa.bindparam("new_value")}),
            filled,
        )


def downgrade() -> None:
    with op.batch_alter_table("take_qa") as batch:
        batch.drop_column(COLUMN)
