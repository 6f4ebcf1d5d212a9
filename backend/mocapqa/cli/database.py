"""``mocapqa db current|upgrade``: the schema revision of the store, and migrating it.

They act on the store named by ``MOCAPQA_DATA_DIR`` (or ``MOCAPQA_DATABASE_URL``), the one
``mocapqa serve`` uses. The server migrates its database itself when it starts; these are for
operators who migrate a PostgreSQL database as a deployment step, before starting new servers
(docs/database.md).
"""

from __future__ import annotations

import typer

from mocapqa.cli.app import app

__all__ = ["db_app"]

db_app = typer.Typer(help="The schema revision of the database.", no_args_is_help=True)
"""The ``mocapqa db`` group."""
app.add_typer(db_app, name="db")


def _database_url() -> str:
    from mocapqa.config import get_settings

    settings = get_settings()
    if not settings.database_url:
        settings.data_dir.mkdir(parents=True, exist_ok=True)
    return settings.resolved_database_url


@db_app.command("current")
def db_current() -> None:
    """Print the database's revision and the newest one; exit 1 unless it is at the newest.

    Reads only: a database made before migrations is shown with the revision its tables match.
    """
    from sqlalchemy import create_engine

    from mocapqa.store.upgrade import current_revision, head_revision, legacy_revision

    engine = create_engine(_database_url())
    try:
        revision = current_revision(engine)
        with engine.connect() as conn:
            legacy = legacy_revision(conn) is not None
    finally:
        engine.dispose()
    head = head_revision()
    shown = revision or "none (empty database)"
    if legacy:
        shown += " (made before migrations, not stamped yet)"
    typer.echo(f"revision: {shown}")
    typer.echo(f"newest:   {head}")
    if revision != head or legacy:
        typer.echo("state:    behind; run `mocapqa db upgrade`")
        raise typer.Exit(1)
    typer.echo("state:    up to date")


@db_app.command("upgrade")
def db_upgrade() -> None:
    """Create the schema or migrate the database to the newest revision (what the server does
    when it starts); prints each step."""
    from sqlalchemy import create_engine

    from mocapqa.store.upgrade import head_revision, upgrade_database

    engine = create_engine(_database_url())
    try:
        done = upgrade_database(engine)
    finally:
        engine.dispose()
    for step in done:
        typer.echo(step)
    typer.echo(f"at {head_revision()}" + ("" if done else " already"))
