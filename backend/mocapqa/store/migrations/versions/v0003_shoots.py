"""Shoots (named collections of takes) and the per-take QA row their tables read.

Revision ID: 0003
Revises: 0002
Created: 2026-12-01 (commit 00e1ef7)

``take_qa`` starts empty here; the store fills the row of every take without one after
migrating (:func:`mocapqa.store.upgrade.upgrade_database`), with the current code's summary.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0003"
down_revision = "0002"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "shoots",
        sa.Column("id", sa.String(32), primary_key=True),
        sa.Column("name", sa.String(255), nullable=False, unique=True),
        sa.Column("created_at", sa.DateTime(timezone=True), nullable=False),
    )
    if op.get_context().dialect.name == "sqlite":
        # SQLite adds a column with its reference in one ALTER (no ADD CONSTRAINT there); a
        # batch "move and copy" of takes would do the same at the cost of copying every row.
        op.execute("ALTER TABLE takes ADD COLUMN shoot_id VARCHAR(32) REFERENCES shoots (id)")
    else:
        op.add_column("takes", sa.Column("shoot_id", sa.String(32), nullable=True))
        op.create_foreign_key("takes_shoot_id_fkey", "takes", "shoots", ["shoot_id"], ["id"])
    op.create_index("ix_takes_shoot_id", "takes", ["shoot_id"])
    op.create_table(
        "take_qa",
        sa.Column(
            "take_id",
            sa.String(32),
            sa.ForeignKey("takes.id", ondelete="CASCADE"),
            primary_key=True,
        ),
        sa.Column("shoot_id", sa.String(32), nullable=True),
        sa.Column("name", sa.String(255), nullable=False),
        sa.Column("kind", sa.String(16), nullable=False),
        sa.Column("created_at", sa.DateTime(timezone=True), nullable=False),
        sa.Column("run_id", sa.String(32), nullable=True),
        sa.Column("status", sa.String(16), nullable=True),
        sa.Column("review_status", sa.String(16), nullable=False),
        sa.Column("reviewer", sa.String(255), nullable=True),
        sa.Column("score", sa.Float(), nullable=True),
        sa.Column("n_frames", sa.Integer(), nullable=True),
        sa.Column("duration_s", sa.Float(), nullable=True),
        sa.Column("rig", sa.String(64), nullable=True),
        sa.Column("twist_intervals", sa.Integer(), nullable=True),
        sa.Column("corrected_joint_frames", sa.Integer(), nullable=True),
        sa.Column("violation_share", sa.Float(), nullable=True),
        sa.Column("worst_joint", sa.String(255), nullable=True),
        sa.Column("filter_residual_mm", sa.Float(), nullable=True),
        sa.Column("missing_share", sa.Float(), nullable=True),
        sa.Column("n_findings", sa.Integer(), nullable=True),
        sa.Column("joint_violations", sa.JSON(), nullable=True),
    )
    for name, column in (
        ("score", "score"),
        ("status", "status"),
        ("review", "review_status"),
        ("created", "created_at"),
        ("name", "name"),
    ):
        op.create_index(f"ix_take_qa_shoot_{name}", "take_qa", ["shoot_id", column])


def downgrade() -> None:
    op.drop_table("take_qa")
    op.drop_index("ix_takes_shoot_id", "takes")
    with op.batch_alter_table("takes") as batch:
        batch.drop_column("shoot_id")
    op.drop_table("shoots")
