"""Shoots get an owner: the user who made one may rename and delete it (admins any).

Revision ID: 0007
Revises: 0006
Created: 2026-12-01

Shoots made before have none, so only an admin deletes or renames them, as before.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0007"
down_revision = "0006"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("shoots") as batch:
        batch.add_column(sa.Column("owner_id", sa.Integer(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("shoots") as batch:
        batch.drop_column("owner_id")
