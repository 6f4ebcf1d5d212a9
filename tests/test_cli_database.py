"""``mocapqa db current|upgrade`` run as an operator would, as a separate process, on a database
made before migrations (SQLite, and PostgreSQL with ``-m postgres``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from sqlalchemy import create_engine, func, select
from tests.store.conftest import database_params
from tests.store.test_migrations import legacy_database

from mocapqa.store.tables import takes
from mocapqa.store.upgrade import head_revision

BACKEND = Path(__file__).resolve().parents[1] / "backend"


def mocapqa(url: str, data_dir: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(BACKEND), "MOCAPQA_DATA_DIR": str(data_dir)}
    env["MOCAPQA_DATABASE_URL"] = url
    return subprocess.run(
        [sys.executable, "-m", "mocapqa.cli.main", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


@pytest.mark.parametrize("kind", database_params())
def test_db_current_and_upgrade(kind: str, tmp_path: Path) -> None:
    url = legacy_database(kind, "a5d24c2", tmp_path)
    head = head_revision()
    before = mocapqa(url, tmp_path, "db", "current")
    assert before.returncode == 1, before.stderr
    assert before.stdout.splitlines() == [
        "revision: 0006 (made before migrations, not stamped yet)",
        f"newest:   {head}",
        "state:    behind; run `mocapqa db upgrade`",
    ]
    upgraded = mocapqa(url, tmp_path, "db", "upgrade")
    assert upgraded.returncode == 0, upgraded.stderr
    assert upgraded.stdout.splitlines() == [
        "stamped a database made before migrations at 0006",
        f"migrated 0006 → {head}",
        f"at {head}",
    ]
    after = mocapqa(url, tmp_path, "db", "current")
    assert after.returncode == 0, after.stderr
    assert after.stdout.splitlines()[-1] == "state:    up to date"
    assert mocapqa(url, tmp_path, "db", "upgrade").stdout.splitlines() == [f"at {head} already"]
    engine = create_engine(url)
    with engine.connect() as conn:
        assert conn.execute(select(func.count()).select_from(takes)).scalar() == 3
    engine.dispose()
