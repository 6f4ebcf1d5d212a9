"""The database schema (SQLAlchemy 2 Core tables), the same on SQLite and PostgreSQL.

Ids are 32-character hex strings made by the repository. Times are UTC. JSON columns hold the
run options and the run summary; the full report and the files live beside the database.
"""

from __future__ import annotations

from sqlalchemy import (
    JSON,
    BigInteger,
    Column,
    DateTime,
    Float,
    ForeignKey,
    Integer,
    MetaData,
    String,
    Table,
    Text,
)

__all__ = ["ADDED_COLUMNS", "metadata", "reviews", "runs", "takes"]

metadata = MetaData()
"""The schema; ``metadata.create_all(engine)`` creates it."""

takes = Table(
    "takes",
    metadata,
    Column("id", String(32), primary_key=True),
    Column("name", String(255), nullable=False),
    Column("format", String(32), nullable=False),
    Column("kind", String(16), nullable=False),
    Column("size_bytes", BigInteger, nullable=False),
    Column("sha256", String(64), nullable=False),
    Column("n_frames", Integer, nullable=False),
    Column("fps", Float, nullable=False),
    Column("n_joints", Integer, nullable=False),
    Column("file_name", String(255), nullable=False),
    Column("created_at", DateTime(timezone=True), nullable=False),
)
"""One row per uploaded take."""

runs = Table(
    "runs",
    metadata,
    Column("id", String(32), primary_key=True),
    Column("take_id", String(32), ForeignKey("takes.id", ondelete="CASCADE"), index=True),
    Column("status", String(16), nullable=False, index=True),
    Column("progress", Integer, nullable=False, default=0),
    Column("step", String(255), nullable=False, default=""),
    Column("options", JSON, nullable=False),
    Column("input_sha256", String(64), nullable=False),
    Column("version", String(32), nullable=False),
    Column("error", Text, nullable=True),
    Column("summary", JSON, nullable=True),
    Column("server_time_s", Float, nullable=True),
    Column("created_at", DateTime(timezone=True), nullable=False),
    Column("started_at", DateTime(timezone=True), nullable=True),
    Column("finished_at", DateTime(timezone=True), nullable=True),
    Column("attempts", Integer, nullable=False, default=0, server_default="0"),
)
"""One row per analysis run; several per take. ``attempts`` counts its starts (a run
interrupted by a server stop is started again, up to a limit)."""

ADDED_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("runs", "attempts", "INTEGER NOT NULL DEFAULT 0"),
)
"""Columns added since the first schema: (table, column, SQL type and default). A database
made before them gets them with ``ALTER TABLE ... ADD COLUMN`` when opened, until schema
migrations take this over."""

reviews = Table(
    "reviews",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("take_id", String(32), ForeignKey("takes.id", ondelete="CASCADE"), index=True),
    Column("status", String(16), nullable=False),
    Column("notes", Text, nullable=False, default=""),
    Column("reviewer", String(255), nullable=False),
    Column("created_at", DateTime(timezone=True), nullable=False),
)
"""Review decisions per take, kept as history."""
