"""Shoots get a joint-limits model: the runs of their takes use it (an admin chooses it).

Revision ID: 0008
Revises: 0007
Created: 2026-12-02

Shoots made before get ``default`` (the shipped choice per rig), what their runs used.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0008"
down_revision = "0007"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("shoots") as batch:
        batch.add_column(
            sa.Column("limits_model", sa.String(64), nullable=False, server_default="default")
        )


def downgrade() -> None:
    with op.batch_alter_table("shoots") as batch:
        batch.drop_column("limits_model")
