"""Alembic's environment: run the migrations on the connection the store passes in.

The store (:func:`mocapqa.store.upgrade.upgrade_database`) builds its configuration in code and
hands over an open connection as ``config.attributes["connection"]``, inside the transaction it
holds. From the command line (``alembic -c backend/mocapqa/store/migrations/alembic.ini``, for
writing a new revision; see docs/database.md) the database comes from ``-x url=...``, then from
``MOCAPQA_DATABASE_URL``.

Alembic runs this file as a script (under its own module name); imported as
``mocapqa.store.migrations.env`` (the documentation test imports every module) it only defines
:func:`run_on`.
"""

from __future__ import annotations

import os

from alembic import context
from sqlalchemy import create_engine
from sqlalchemy.engine import Connection

from mocapqa.store.tables import metadata


def run_on(connection: Connection) -> None:
    """Run the requested migrations on ``connection`` (batch mode: SQLite cannot ALTER much)."""
    context.configure(
        connection=connection,
        target_metadata=metadata,
        render_as_batch=True,
        compare_type=True,
    )
    with context.begin_transaction():
        context.run_migrations()


def _url() -> str:
    url = context.get_x_argument(as_dictionary=True).get("url") or os.environ.get(
        "MOCAPQA_DATABASE_URL", ""
    )
    if not url:
        raise SystemExit(
            "Expected the database as '-x url=sqlite:///path' or MOCAPQA_DATABASE_URL, got neither"
        )
    return url


def main() -> None:
    """Migrate the connection given in the configuration, or the database named on the command
    line."""
    if context.is_offline_mode():
        raise SystemExit("Expected an online migration (the store's migrations need a connection)")
    given = context.config.attributes.get("connection")
    if isinstance(given, Connection):
        run_on(given)
        return
    engine = create_engine(_url())
    with engine.connect() as connection:
        run_on(connection)
    engine.dispose()


if not __name__.startswith("mocapqa."):
    main()
