"""The database schema (SQLAlchemy 2 Core tables), the same on SQLite and PostgreSQL.

Ids are 32-character hex strings made by the repository. Times are UTC. JSON columns hold the
run options and the run summary; the full report and the files live beside the database.
"""

from __future__ import annotations

from sqlalchemy import (
    JSON,
    BigInteger,
    Boolean,
    Column,
    DateTime,
    Float,
    ForeignKey,
    Index,
    Integer,
    MetaData,
    String,
    Table,
    Text,
)

__all__ = [
    "audit",
    "interval_decisions",
    "metadata",
    "reviews",
    "runs",
    "shoots",
    "source_hashes",
    "take_qa",
    "takes",
    "tokens",
    "users",
]

metadata = MetaData()
"""The schema. Databases are created and upgraded by the migrations in ``store/migrations``
(:func:`mocapqa.store.upgrade.upgrade_database`): a change here needs a new revision there, and
``tests/store/test_migrations.py`` fails until the migrated schema matches this one
(docs/database.md)."""

shoots = Table(
    "shoots",
    metadata,
    Column("id", String(32), primary_key=True),
    Column("name", String(255), nullable=False, unique=True),
    Column("created_at", DateTime(timezone=True), nullable=False),
    Column("owner_id", Integer, nullable=True),
    Column("limits_model", String(64), nullable=False, server_default="default"),
)
"""Named collections of takes; a take belongs to at most one. ``owner_id`` is the user who made
the shoot (none for shoots made before shoots had owners, or while the server had no users).
``limits_model`` names the joint-limits model its takes' runs use (:mod:`mocapqa.limits.catalog`;
an admin chooses it)."""

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
    Column("shoot_id", String(32), ForeignKey("shoots.id"), nullable=True, index=True),
    Column("owner_id", Integer, nullable=True, index=True),
)
"""One row per uploaded take; ``owner_id`` is the user who uploaded it (none for takes
uploaded before accounts, or while the server had no users)."""

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

reviews = Table(
    "reviews",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("take_id", String(32), ForeignKey("takes.id", ondelete="CASCADE"), index=True),
    Column("status", String(16), nullable=False),
    Column("notes", Text, nullable=False, default=""),
    Column("reviewer", String(255), nullable=False),
    Column("created_at", DateTime(timezone=True), nullable=False),
    Column("user_id", Integer, nullable=True),
)
"""Review decisions per take, kept as history. ``reviewer`` is the signed-in user's name
(``user_id`` their id); reviews made before accounts keep the free-text name they were given."""

take_qa = Table(
    "take_qa",
    metadata,
    Column("take_id", String(32), ForeignKey("takes.id", ondelete="CASCADE"), primary_key=True),
    Column("shoot_id", String(32), nullable=True),
    Column("name", String(255), nullable=False),
    Column("kind", String(16), nullable=False),
    Column("created_at", DateTime(timezone=True), nullable=False),
    Column("run_id", String(32), nullable=True),
    Column("status", String(16), nullable=True),
    Column("review_status", String(16), nullable=False),
    Column("reviewer", String(255), nullable=True),
    Column("score", Float, nullable=True),
    Column("n_frames", Integer, nullable=True),
    Column("duration_s", Float, nullable=True),
    Column("rig", String(64), nullable=True),
    Column("twist_intervals", Integer, nullable=True),
    Column("corrected_joint_frames", Integer, nullable=True),
    Column("limb_spins", Integer, nullable=True),
    Column("violation_share", Float, nullable=True),
    Column("worst_joint", String(255), nullable=True),
    Column("filter_residual_mm", Float, nullable=True),
    Column("missing_share", Float, nullable=True),
    Column("n_findings", Integer, nullable=True),
    Column("foot_skates", Integer, nullable=True),
    Column("foot_worst_skate", Float, nullable=True),
    Column("foot_skate_unit", String(16), nullable=True),
    Column("foot_penetrations", Integer, nullable=True),
    Column("foot_floating", Integer, nullable=True),
    Column("foot_worst_skate_pct", Float, nullable=True),
    Column("joint_violations", JSON, nullable=True),
    Index("ix_take_qa_shoot_score", "shoot_id", "score"),
    Index("ix_take_qa_shoot_status", "shoot_id", "status"),
    Index("ix_take_qa_shoot_review", "shoot_id", "review_status"),
    Index("ix_take_qa_shoot_created", "shoot_id", "created_at"),
    Index("ix_take_qa_shoot_name", "shoot_id", "name"),
)
"""One row per take: its latest run's status and QA summary and its latest review, kept in step
by the repository so that a shoot's take table sorts and filters on indexed columns. The
``foot_*`` columns are the feet step's skate, penetration and floating counts and its largest
skate (``foot_worst_skate`` in ``foot_skate_unit``: cm, or % of the body height when the take's
unit does not convert) and, in ``foot_worst_skate_pct``, the largest skate in % of the body
height the feet check estimates, the same measure for every take (the table sorts by it;
revision 0012); null for a run that did not check the feet (or was made before these columns),
and the largest skate null too when no skate was found."""

source_hashes = Table(
    "source_hashes",
    metadata,
    Column("path", String(1024), primary_key=True),
    Column("size_bytes", BigInteger, nullable=False),
    Column("mtime_ns", BigInteger, nullable=False),
    Column("sha256", String(64), nullable=False),
)
"""Content hashes of batch source files by path, size and modification time, so resuming a
batch stats its files instead of reading them again."""

interval_decisions = Table(
    "interval_decisions",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("run_id", String(32), ForeignKey("runs.id", ondelete="CASCADE"), index=True),
    Column("interval_id", Integer, nullable=True),
    Column("decision", String(16), nullable=False),
    Column("note", Text, nullable=False, default=""),
    Column("reviewer", String(255), nullable=False),
    Column("client", String(255), nullable=False),
    Column("created_at", DateTime(timezone=True), nullable=False),
    Column("item_kind", String(16), nullable=False, server_default="correction"),
    Column("lock_id", String(64), nullable=True),
)
"""A reviewer's accept / reject of one item of a run, kept as history (the newest row per item
is the decision; ``client`` is where it came from). ``item_kind`` says what the row decides:
``"correction"``, the run's twist interval or swap ``interval_id`` (every row made before
revision 0011), or ``"lock"``, the foot lock of the run's skate finding ``lock_id``
(``interval_id`` null)."""

users = Table(
    "users",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("name", String(64), nullable=False, unique=True),
    Column("role", String(16), nullable=False),
    Column("password_hash", Text, nullable=True),
    Column("disabled", Boolean, nullable=False, default=False),
    Column("created_at", DateTime(timezone=True), nullable=False),
)
"""Accounts. ``password_hash`` is an argon2 hash (none for a token-only user)."""

tokens = Table(
    "tokens",
    metadata,
    Column("id", String(32), primary_key=True),
    Column("user_id", Integer, ForeignKey("users.id", ondelete="CASCADE"), index=True),
    Column("kind", String(16), nullable=False),
    Column("name", String(255), nullable=False, default=""),
    Column("secret_sha256", String(64), nullable=False),
    Column("csrf", String(64), nullable=True),
    Column("created_at", DateTime(timezone=True), nullable=False),
    Column("expires_at", DateTime(timezone=True), nullable=False),
    Column("last_used_at", DateTime(timezone=True), nullable=True),
    Column("revoked_at", DateTime(timezone=True), nullable=True),
)
"""Credentials of three kinds: ``api`` (personal tokens), ``session`` (a browser's sign-in,
with its CSRF token) and ``link`` (a one-time sign-in link). Only the SHA-256 of the secret is
stored: the secrets are 256 random bits, so a fast hash is enough (passwords get argon2)."""

audit = Table(
    "audit",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("at", DateTime(timezone=True), nullable=False, index=True),
    Column("user_id", Integer, nullable=True),
    Column("user_name", String(64), nullable=True),
    Column("action", String(32), nullable=False),
    Column("target", String(255), nullable=False, default=""),
    Column("detail", Text, nullable=False, default=""),
    Column("client", String(64), nullable=False, default=""),
)
"""Append-only record of who did what, when and from where (no API route edits it)."""
