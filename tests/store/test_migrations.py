"""Schema migrations on SQLite and on a real PostgreSQL (``-m postgres``).

The databases in ``tests/data/legacy`` were made by the project's own code at older commits,
before it had migrations (tests/data/legacy/README.md): opening one with the current code must
stamp it at the right revision, migrate it to the newest, keep every row and value, and leave
the schema the models declare, with the app working on it.
"""

from __future__ import annotations

import shutil
import sqlite3
from concurrent.futures import ThreadPoolExecutor
from datetime import timedelta
from pathlib import Path
from typing import Any

import psycopg
import pytest
from alembic.autogenerate import compare_metadata
from alembic.runtime.migration import MigrationContext
from fastapi.testclient import TestClient
from sqlalchemy import Column, Engine, Integer, MetaData, create_engine, inspect, select, text
from tests.store.conftest import database_params, database_url

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.errors import ConflictError
from mocapqa.store.repository import Repository
from mocapqa.store.tables import metadata
from mocapqa.store.upgrade import (
    current_revision,
    downgrade_database,
    head_revision,
    schema_difference,
    upgrade_database,
)

LEGACY = Path(__file__).resolve().parents[1] / "data" / "legacy"
REVISION_OF = {
    "228f57d": "0001",
    "4ffc0b1": "0005",
    "a5d24c2": "0006",
    "228f57d-then-a5d24c2": "0006",
}
"""Each legacy database and the revision its schema is (tests/data/legacy/README.md)."""


def legacy_database(kind: str, name: str, tmp_path: Path) -> str:
    """A copy of the legacy database ``name`` on ``kind``: the SQLite file, or the PostgreSQL
    dump loaded into the clean test database."""
    if kind == "sqlite":
        copy = tmp_path / f"{name}.sqlite3"
        shutil.copyfile(LEGACY / f"{name}.sqlite3", copy)
        return f"sqlite:///{copy}"
    url = database_url(kind, tmp_path)
    dump = (LEGACY / f"{name}.postgres.sql").read_text(encoding="utf-8")
    with psycopg.connect(url.replace("postgresql+psycopg", "postgresql"), autocommit=True) as pg:
        pg.execute("DROP SCHEMA public CASCADE")
        pg.execute("CREATE SCHEMA public")
        pg.execute(dump.encode())
    return url


def snapshot(engine: Engine) -> dict[str, dict[tuple[Any, ...], dict[str, Any]]]:
    """Every row of every table, by primary key."""
    found = MetaData()
    found.reflect(engine)
    rows: dict[str, dict[tuple[Any, ...], dict[str, Any]]] = {}
    with engine.connect() as conn:
        for name, table in found.tables.items():
            if name == "alembic_version":
                continue
            keys = [c.name for c in table.primary_key.columns]
            rows[name] = {
                tuple(r[k] for k in keys): dict(r) for r in conn.execute(select(table)).mappings()
            }
    return rows


def lost_values(
    before: dict[str, dict[tuple[Any, ...], dict[str, Any]]],
    after: dict[str, dict[tuple[Any, ...], dict[str, Any]]],
) -> list[str]:
    """Rows or values of ``before`` that ``after`` does not hold."""
    lost = []
    for table, rows in before.items():
        for key, row in rows.items():
            kept = after.get(table, {}).get(key)
            if kept is None:
                lost.append(f"{table} {key}: row gone")
                continue
            lost += [
                f"{table} {key}.{column}: {value!r} → {kept.get(column)!r}"
                for column, value in row.items()
                if kept.get(column) != value
            ]
    return lost


def use_the_app(url: str, data_dir: Path, before: dict[str, Any]) -> None:
    """List the takes, read every run and review and write a review through the API."""
    settings = Settings(data_dir=data_dir, database_url=url, allowed_hosts=["testserver"])
    app = create_app(settings)
    with TestClient(app) as client:
        accounts = app.state.accounts
        headers = {}
        if accounts.has_users():
            # the user the old version made: its argon2 hash still signs it in
            user = accounts.check_password("ana", "correct horse battery")
            token = accounts.issue(user.id, "api", timedelta(days=1)).token
            headers = {"Authorization": f"Bearer {token}"}
        page = client.get("/api/v1/takes?limit=500", headers=headers)
        assert page.status_code == 200, page.text
        assert {t["id"] for t in page.json()["items"]} == {k[0] for k in before["takes"]}
        for (run_id,), run in before["runs"].items():
            answer = client.get(f"/api/v1/runs/{run_id}", headers=headers)
            assert answer.status_code == 200, answer.text
            assert answer.json()["status"] == run["status"]
            assert answer.json()["summary"] == run["summary"]
        for (take_id,) in before["takes"]:
            reviews = client.get(f"/api/v1/takes/{take_id}/reviews", headers=headers).json()
            had = sorted(r["notes"] for r in before["reviews"].values() if r["take_id"] == take_id)
            assert sorted(r["notes"] for r in reviews) == had
        take_id = next(iter(before["takes"]))[0]
        review = {"status": "rejected", "notes": "after the upgrade"}
        added = client.post(f"/api/v1/takes/{take_id}/reviews", json=review, headers=headers)
        assert added.status_code == 201, added.text
        assert client.get(f"/api/v1/takes/{take_id}", headers=headers).json()["review_status"] == (
            "rejected"
        )


@pytest.mark.parametrize("name", list(REVISION_OF))
@pytest.mark.parametrize("kind", database_params())
def test_a_database_made_before_migrations_is_upgraded_and_loses_nothing(
    kind: str, name: str, tmp_path: Path
) -> None:
    url = legacy_database(kind, name, tmp_path)
    engine = create_engine(url)
    assert current_revision(engine) == REVISION_OF[name]
    before = snapshot(engine)
    engine.dispose()
    assert len(before["takes"]) >= 2
    assert len(before["runs"]) >= 3
    assert len(before["reviews"]) == 2

    repository = Repository(url)
    stamped = f"stamped a database made before migrations at {REVISION_OF[name]}"
    assert stamped in repository.upgrades
    after = snapshot(repository.engine)
    assert lost_values(before, after) == []
    assert schema_difference(repository.engine) == []
    assert current_revision(repository.engine) == head_revision()
    assert set(after["take_qa"]) == set(after["takes"])
    repository.close()
    again = Repository(url)
    assert again.upgrades == []
    again.close()
    use_the_app(url, tmp_path / "data", before)


@pytest.mark.parametrize("kind", database_params())
def test_the_migrations_make_the_schema_of_the_models(kind: str, tmp_path: Path) -> None:
    repository = Repository(database_url(kind, tmp_path))
    assert repository.upgrades == [f"migrated an empty database → {head_revision()}"]
    assert schema_difference(repository.engine) == []
    # a model edited without a migration is found: a column more in the models...
    edited = MetaData()
    for table in metadata.tables.values():
        table.to_metadata(edited)
    edited.tables["shoots"].append_column(Column("colour", Integer))
    with repository.engine.connect() as conn:
        found = compare_metadata(MigrationContext.configure(conn), edited)
    assert [(d[0], d[2], d[3].name) for d in found] == [("add_column", "shoots", "colour")]
    # ...and an index the models do not declare
    with repository.engine.begin() as conn:
        conn.execute(text("CREATE INDEX ix_takes_name ON takes (name)"))
    assert [d[0] for d in schema_difference(repository.engine)] == ["remove_index"]
    repository.close()


@pytest.mark.parametrize("kind", database_params())
def test_databases_opened_at_once_are_migrated_once(kind: str, tmp_path: Path) -> None:
    url = database_url(kind, tmp_path)

    def open_one(_: int) -> list[str]:
        repository = Repository(url)
        repository.close()
        return repository.upgrades

    with ThreadPoolExecutor(4) as pool:
        done = list(pool.map(open_one, range(4)))
    assert sorted(len(d) for d in done) == [0, 0, 0, 1]


@pytest.mark.parametrize("kind", database_params())
def test_downgrade_to_an_older_revision_keeps_its_rows(kind: str, tmp_path: Path) -> None:
    repository = Repository(database_url(kind, tmp_path))
    with repository.engine.begin() as conn:
        conn.execute(
            text("INSERT INTO shoots (id, name, created_at) VALUES ('s1', 'day', :t)"),
            {"t": "2026-01-01T00:00:00+00:00"},
        )
    downgrade_database(repository.engine, "0005")
    assert current_revision(repository.engine) == "0005"
    tables = set(inspect(repository.engine).get_table_names())
    assert "users" not in tables
    assert upgrade_database(repository.engine)[0] == f"migrated 0005 → {head_revision()}"
    assert schema_difference(repository.engine) == []
    with repository.engine.connect() as conn:
        assert conn.execute(text("SELECT name FROM shoots")).scalars().all() == ["day"]
    downgrade_database(repository.engine, "base")
    assert set(inspect(repository.engine).get_table_names()) <= {"alembic_version"}
    repository.close()


def test_a_database_this_project_did_not_make_is_refused_untouched(tmp_path: Path) -> None:
    path = tmp_path / "other.sqlite3"
    with sqlite3.connect(path) as conn:
        conn.execute("CREATE TABLE takes (id VARCHAR(32) PRIMARY KEY, title TEXT)")
        conn.execute("INSERT INTO takes VALUES ('a', 'mine')")
    with pytest.raises(ConflictError, match=r"revision 0001 has takes, runs, reviews\), got takes"):
        Repository(f"sqlite:///{path}")
    with sqlite3.connect(path) as conn:
        tables = [r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")]
        assert tables == ["takes"]
        assert conn.execute("SELECT * FROM takes").fetchall() == [("a", "mine")]


def test_a_reference_broken_before_migrating_does_not_stop_it(tmp_path: Path) -> None:
    """SQLite checks references after migrating; one the old database already broke (its
    foreign keys were off) is kept as it was, not counted against the migration."""
    url = legacy_database("sqlite", "228f57d", tmp_path)
    with sqlite3.connect(url.removeprefix("sqlite:///")) as conn:
        conn.execute(
            "INSERT INTO reviews (take_id, status, notes, reviewer, created_at)"
            " VALUES ('gone', 'approved', 'orphan', 'ann', '2026-01-01 00:00:00')"
        )
    repository = Repository(url)
    with repository.engine.connect() as conn:
        notes = conn.execute(text("SELECT notes FROM reviews WHERE take_id = 'gone'")).scalars()
        assert notes.all() == ["orphan"]
    assert current_revision(repository.engine) == head_revision()
    repository.close()
