"""Create a database, or bring one made by an earlier version up to the current schema, in place.

The schema's history is the Alembic migrations in ``store/migrations/versions`` (one revision per
change, ``0001`` being the first released schema). :func:`upgrade_database` runs
``alembic upgrade head`` on the store's own connection, with a configuration built here (no
``alembic.ini`` at run time), in one transaction that other processes opening the same database
wait for (a PostgreSQL advisory lock; SQLite's ``BEGIN IMMEDIATE``).

A database made before the project had migrations has no ``alembic_version`` table. Its
revision is read from what it holds (:data:`LEGACY_MARKERS`: each released schema added a table
or a column that the previous one lacked), it is stamped with that revision and migrated on from
there; no row is touched. Afterwards, every take without a ``take_qa`` row gets one (the shoots
revision makes that table empty).

SQLite's foreign keys are off while migrating: a batch migration rebuilds a table by copying it,
and dropping the old copy must not cascade into the rows that refer to it; the database's
references are checked (``PRAGMA foreign_key_check``: no more broken ones than before) before
the transaction commits.
"""

from __future__ import annotations

import logging
from functools import cache
from pathlib import Path
from typing import Any

from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from sqlalchemy import Engine, inspect, select, text
from sqlalchemy.engine import Connection

from mocapqa.errors import ConflictError
from mocapqa.store.qa import sync_take
from mocapqa.store.tables import metadata, take_qa, takes

__all__ = [
    "LEGACY_MARKERS",
    "MIGRATIONS",
    "alembic_config",
    "current_revision",
    "downgrade_database",
    "drop_database",
    "head_revision",
    "legacy_revision",
    "schema_difference",
    "upgrade_database",
]

MIGRATIONS = Path(__file__).with_name("migrations")
"""The Alembic script folder (shipped inside the package)."""

LEGACY_MARKERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("0001", ("takes", "runs", "reviews")),
    ("0002", ("runs.attempts",)),
    ("0003", ("shoots", "take_qa", "takes.shoot_id")),
    ("0004", ("source_hashes",)),
    ("0005", ("interval_decisions",)),
    ("0006", ("users", "tokens", "audit", "takes.owner_id", "reviews.user_id")),
)
"""(revision, the tables and ``table.column``s it added): a database made before migrations
holds revision N's schema when it has everything N and the revisions before it added. The code
of those versions created all its tables and added its columns whenever it opened a database,
so a version's additions come all together or not at all."""

# Alembic logs its set-up at INFO on every open; the store logs what it changed instead.
logging.getLogger("alembic").setLevel(logging.WARNING)

_LOCK_KEY = 0x6D6F6361
"""PostgreSQL advisory lock id held while migrating ("moca")."""


def alembic_config(connection: Connection | None = None) -> Config:
    """Alembic's configuration for the store's migrations, built in code.

    Parameters
    ----------
    connection : Connection, optional
        The connection ``env.py`` migrates (``config.attributes["connection"]``).
    """
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    config.attributes["connection"] = connection
    return config


def head_revision() -> str:
    """The newest revision of the migration history (read once per process)."""
    return _head()


@cache
def _head() -> str:
    head = ScriptDirectory.from_config(alembic_config()).get_current_head()
    if head is None:  # pragma: no cover - the package ships its revisions
        raise RuntimeError(f"no migration found in {MIGRATIONS}")
    return head


def legacy_revision(connection: Connection) -> str | None:
    """The revision a database made before migrations holds (None: not such a database).

    A database with an ``alembic_version`` table, or without a ``takes`` table, is not one.

    Raises
    ------
    ConflictError
        Part of a revision's tables or columns only: not a database this project made.
    """
    inspector = inspect(connection)
    tables = set(inspector.get_table_names())
    if "alembic_version" in tables or "takes" not in tables:
        return None

    def has(marker: str) -> bool:
        table, _, column = marker.partition(".")
        if table not in tables:
            return False
        return not column or column in {c["name"] for c in inspector.get_columns(table)}

    found = None
    for revision, markers in LEGACY_MARKERS:
        present = [marker for marker in markers if has(marker)]
        if len(present) < len(markers):
            if present or found is None:
                raise ConflictError(
                    f"Expected a database made by mocapqa (revision {revision} has "
                    f"{', '.join(markers)}), got {', '.join(present) or 'none of them'} "
                    f"beside {', '.join(sorted(tables))}"
                )
            break
        found = revision
    return found


def current_revision(engine: Engine) -> str | None:
    """The database's revision: ``alembic_version``'s, else the legacy one read from its
    tables (:func:`legacy_revision`), else None (an empty database)."""
    with engine.connect() as conn:
        stamped = MigrationContext.configure(conn).get_current_revision()
        return stamped if stamped is not None else legacy_revision(conn)


def schema_difference(engine: Engine) -> list[Any]:
    """What Alembic's autogenerate finds between the database and the models
    (:data:`~mocapqa.store.tables.metadata`): empty when the migrations made exactly the
    schema the code declares (a model edited without a migration shows up here)."""
    from alembic.autogenerate import compare_metadata  # loads its plugins: only when asked

    with engine.connect() as conn:
        context = MigrationContext.configure(conn, opts={"compare_type": True})
        return list(compare_metadata(context, metadata))


def _repair_legacy(conn: Connection, revision: str) -> list[str]:
    # Versions before migrations added ``takes.owner_id`` to an older database by ALTER TABLE
    # without the index they gave it in a new one.
    if revision != "0006":
        return []
    indexes = {ix["name"] for ix in inspect(conn).get_indexes("takes")}
    if "ix_takes_owner_id" in indexes:
        return []
    conn.execute(text("CREATE INDEX ix_takes_owner_id ON takes (owner_id)"))
    return ["created the index ix_takes_owner_id"]


def _fill_take_qa(conn: Connection) -> list[str]:
    missing = [
        str(take_id)
        for take_id in conn.execute(
            select(takes.c.id).where(~takes.c.id.in_(select(take_qa.c.take_id)))
        ).scalars()
    ]
    for take_id in missing:
        sync_take(conn, take_id)
    return [f"filled take_qa for {len(missing)} take(s)"] if missing else []


def _broken_references(conn: Connection) -> list[Any]:
    return list(conn.exec_driver_sql("PRAGMA foreign_key_check").fetchall())


def _check_references(conn: Connection, before: int) -> None:
    broken = _broken_references(conn)
    if len(broken) > before:
        raise ConflictError(
            f"Expected the references to hold after migrating as before ({before} broken), got "
            f"{len(broken)} broken (first: table {broken[0][0]!r} row {broken[0][1]} → "
            f"{broken[0][2]!r})"
        )


def _migrate(engine: Engine, target: str, downgrade: bool = False) -> list[str]:
    sqlite = engine.dialect.name == "sqlite"
    done: list[str] = []
    if target == "head":
        # the common case, without a lock or a write: already at the newest revision
        with engine.connect() as conn:
            if MigrationContext.configure(conn).get_current_revision() == head_revision():
                return done
    broken_before = 0
    with engine.connect() as conn:
        if sqlite:
            conn.exec_driver_sql("PRAGMA foreign_keys=OFF")
            conn.commit()
        try:
            if sqlite:
                conn.exec_driver_sql("BEGIN IMMEDIATE")
                broken_before = len(_broken_references(conn))
            else:
                conn.execute(text("SELECT pg_advisory_xact_lock(:key)"), {"key": _LOCK_KEY})
            config = alembic_config(conn)
            legacy = legacy_revision(conn)
            if legacy is not None:
                done += _repair_legacy(conn, legacy)
                command.stamp(config, legacy)
                done.append(f"stamped a database made before migrations at {legacy}")
            before = MigrationContext.configure(conn).get_current_revision()
            if downgrade:
                command.downgrade(config, target)
            else:
                command.upgrade(config, target)
            after = MigrationContext.configure(conn).get_current_revision()
            if after != before:
                done.append(f"migrated {before or 'an empty database'} → {after or 'none'}")
            if after is not None and not downgrade:
                done += _fill_take_qa(conn)
            if sqlite:
                _check_references(conn, broken_before)
            conn.commit()
        finally:
            if sqlite:
                conn.rollback()
                conn.exec_driver_sql("PRAGMA foreign_keys=ON")
                conn.commit()
    return done


def upgrade_database(engine: Engine) -> list[str]:
    """Create the schema, or migrate the database to the newest revision; returns what was
    done (for the log; empty when it was up to date).

    Raises
    ------
    ConflictError
        Migrating would leave a broken reference (SQLite; nothing is changed).
    """
    return _migrate(engine, "head")


def downgrade_database(engine: Engine, revision: str) -> list[str]:
    """Migrate the database back to ``revision`` (``base``: no table left)."""
    return _migrate(engine, revision, downgrade=True)


def drop_database(engine: Engine) -> None:
    """Drop every table of the store, the migration stamp included (tests and benchmarks start
    over this way)."""
    with engine.begin() as conn:
        metadata.drop_all(conn)
        conn.execute(text("DROP TABLE IF EXISTS alembic_version"))
