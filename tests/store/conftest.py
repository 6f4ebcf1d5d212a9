"""Repository fixtures: a temporary SQLite, and the real PostgreSQL when one is given."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest
from sqlalchemy import create_engine

from mocapqa.store.repository import Repository
from mocapqa.store.upgrade import drop_database


def database_params() -> list[object]:
    """``sqlite`` always; ``postgres`` (marked) runs when MOCAPQA_TEST_POSTGRES_URL is set."""
    return ["sqlite", pytest.param("postgres", marks=pytest.mark.postgres)]


def database_url(kind: str, tmp_path: Path) -> str:
    """A clean database of ``kind`` (the PostgreSQL schema is dropped and recreated)."""
    if kind == "sqlite":
        return f"sqlite:///{tmp_path / 'test.sqlite3'}"
    url = os.environ.get("MOCAPQA_TEST_POSTGRES_URL")
    if not url:
        pytest.skip("MOCAPQA_TEST_POSTGRES_URL is not set (scripts/with-postgres.sh sets it)")
    clean_database(url)
    return url


def clean_database(url: str) -> None:
    """Drop the store's tables and its migration stamp, without migrating first."""
    engine = create_engine(url)
    drop_database(engine)
    engine.dispose()


@pytest.fixture(params=database_params())
def repository(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Repository]:
    """A repository on an empty database."""
    repo = Repository(database_url(str(request.param), tmp_path))
    yield repo
    repo.close()
