"""API fixtures: ``TestClient(create_app(settings))`` on a temporary SQLite and on PostgreSQL."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from tests.store.conftest import clean_database

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.render.service import RenderService


def make_settings(kind: str, tmp_path: Path, **changes: Any) -> Settings:
    """Settings with a fresh data folder and a clean database of ``kind``."""
    url = None
    if kind == "postgres":
        url = os.environ.get("MOCAPQA_TEST_POSTGRES_URL")
        if not url:
            pytest.skip("MOCAPQA_TEST_POSTGRES_URL is not set (scripts/with-postgres.sh sets it)")
        clean_database(url)
    changes.setdefault("allowed_hosts", ["testserver", "localhost", "127.0.0.1"])
    return Settings(data_dir=tmp_path / "data", database_url=url, **changes)


@pytest.fixture(params=["sqlite", pytest.param("postgres", marks=pytest.mark.postgres)])
def settings(request: pytest.FixtureRequest, tmp_path: Path) -> Settings:
    """Settings for one database kind."""
    return make_settings(str(request.param), tmp_path)


@pytest.fixture(scope="session")
def renderer() -> Iterator[RenderService]:
    """One render thread for every app of the session (VTK starts once)."""
    with RenderService() as service:
        yield service


@pytest.fixture
def client(settings: Settings, renderer: RenderService) -> Iterator[TestClient]:
    """A client of a freshly created app."""
    with TestClient(create_app(settings, renderer=renderer)) as test_client:
        yield test_client


RUN_BOUND_S = 900.0
"""Generous bound on one run: a render-heavy run that needs well under a minute on an idle
machine has taken more than that on a loaded 2-core one. A failure to finish is a hang, not a
slow machine."""


def poll_run(client: TestClient, run_id: str, timeout_s: float = RUN_BOUND_S) -> dict[str, Any]:
    """Poll a run until it is done or failed (at most ``timeout_s``, a generous bound)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        run: dict[str, Any] = client.get(f"/api/v1/runs/{run_id}").json()
        if run["status"] in ("done", "failed"):
            return run
        time.sleep(0.05)
    raise TimeoutError(f"run {run_id} did not finish in {timeout_s} s")


def post_file(client: TestClient, path: Path, name: str | None = None) -> dict[str, Any]:
    """Upload a file and return the 201 body."""
    with path.open("rb") as handle:
        response = client.post("/api/v1/takes", files={"file": (name or path.name, handle)})
    assert response.status_code == 201, response.text
    body: dict[str, Any] = response.json()
    return body


Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]


@pytest.fixture
def wait_for_run() -> Waiter:
    """``wait_for_run(client, run_id)`` polls until the run is done or failed."""
    return poll_run


@pytest.fixture
def upload() -> Uploader:
    """``upload(client, path)`` posts a file and returns the 201 body."""
    return post_file
