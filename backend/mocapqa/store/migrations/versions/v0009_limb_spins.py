"""Take rows get the number of limb spins and flips their latest run reported.

Revision ID: 0009
Revises: 0008
Created: 2026-12-02

Rows of runs made before stay empty (null) until the take is analysed again: those runs did
not look for spins.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0009"
down_revision = "0008"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("take_qa") as batch:
        batch.add_column(sa.Column("limb_spins", sa.Integer(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("take_qa") as batch:
        batch.drop_column("limb_spins")
