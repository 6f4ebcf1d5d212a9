"""Decisions on a second kind of item: the foot locks of a run's skate findings.

Revision ID: 0011
Revises: 0010
Created: 2026-12-05

``interval_decisions`` gains ``item_kind`` (``"correction"``: a twist interval or swap, by
``interval_id``; ``"lock"``: a foot lock, by ``lock_id``) and ``lock_id``; ``interval_id``
may be null (a lock's row). Every row made before keeps its meaning: ``item_kind`` is
``"correction"`` for all of them (the server default) and ``lock_id`` null.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0011"
down_revision = "0010"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("interval_decisions") as batch:
        batch.add_column(
            sa.Column("item_kind", sa.String(16), nullable=False, server_default="correction")
        )
        batch.add_column(sa.Column("lock_id", sa.String(64), nullable=True))
        batch.alter_column("interval_id", existing_type=sa.Integer(), nullable=True)


def downgrade() -> None:
    op.execute(sa.text("DELETE FROM interval_decisions WHERE item_kind <> 'correction'"))
    with op.batch_alter_table("interval_decisions") as batch:
        batch.alter_column("interval_id", existing_type=sa.Integer(), nullable=False)
        batch.drop_column("lock_id")
        batch.drop_column("item_kind")
