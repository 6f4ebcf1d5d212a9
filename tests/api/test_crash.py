"""The real server killed (SIGKILL) in the middle of a run, then started again.

The run is re-queued and finishes; a run whose server is killed during it twice is failed with
the reason instead of being started a third time; the database stays intact throughout.
Every wait is a poll with a generous bound (a loaded 2-core machine), never a deadline.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from collections.abc import Callable
from datetime import timedelta
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.live_server import free_port

from mocapqa.cli.serve import FIRST_ADMIN
from mocapqa.store.accounts import Accounts
from mocapqa.store.repository import Repository

BOUND_S = 900.0
"""Generous bound on any one wait."""
REPEATS = 20
"""The CMU walk repeated this many times: ~10,500 frames, a run of several seconds."""


def long_take(cmu_walk: Path, tmp_path: Path) -> Path:
    """The walk with its frames repeated, so the run lasts long enough to be killed in."""
    text = cmu_walk.read_text()
    head, _, frames = text.partition("MOTION\n")
    lines = frames.split("\n")
    rows = [line for line in lines[2:] if line.strip()]
    body = "\n".join(rows * REPEATS)
    path = tmp_path / "long_walk.bvh"
    path.write_text(f"{head}MOTION\nFrames: {len(rows) * REPEATS}\n{lines[1]}\n{body}\n")
    return path


def poll(what: str, check: Callable[[], Any]) -> Any:
    """Call ``check`` until it returns something truthy (at most :data:`BOUND_S`)."""
    deadline = time.monotonic() + BOUND_S
    while time.monotonic() < deadline:
        try:
            found = check()
        except httpx.HTTPError:
            found = None
        if found:
            return found
        time.sleep(0.05)
    raise TimeoutError(f"{what}: not within {BOUND_S} s")


def admin_bearer(data_dir: Path) -> dict[str, str]:
    """An ``Authorization`` header for the admin ``serve`` made in ``data_dir``."""
    repository = Repository(f"sqlite:///{data_dir / 'mocapqa.sqlite3'}")
    try:
        accounts = Accounts(repository.engine)
        token = accounts.issue(accounts.get_user(FIRST_ADMIN).id, "api", timedelta(days=1))
    finally:
        repository.close()
    return {"Authorization": f"Bearer {token.token}"}


class Server:
    """``mocapqa serve`` as a child process on a data folder."""

    def __init__(self, data_dir: Path) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        root = Path(__file__).resolve().parents[2]
        env = {
            **os.environ,
            "PYTHONPATH": str(root / "backend"),
            "MOCAPQA_DATA_DIR": str(data_dir),
            "MOCAPQA_JOB_WORKERS": "1",
        }
        env.pop("MOCAPQA_DATABASE_URL", None)
        command = [sys.executable, "-m", "mocapqa.cli.main", "serve", "--port", str(self.port)]
        self.process = subprocess.Popen(
            command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
        )
        poll("server start", lambda: httpx.get(f"{self.url}/api/v1/health").is_success)
        # `serve` made an admin on its first start: the test acts as it, through a token.
        self.client = httpx.Client(headers=admin_bearer(data_dir), timeout=300)

    def run(self, run_id: str) -> dict[str, Any]:
        """The run's current state."""
        answer: dict[str, Any] = self.client.get(f"{self.url}/api/v1/runs/{run_id}").json()
        return answer

    def kill(self) -> None:
        """SIGKILL, as a crash would."""
        os.kill(self.process.pid, signal.SIGKILL)
        self.process.wait(timeout=60)

    def stop(self) -> None:
        """SIGTERM and wait."""
        if self.process.poll() is None:
            self.process.terminate()
            self.process.wait(timeout=120)


def kill_while_running(server: Server, run_id: str) -> None:
    """Wait until the run is running, then kill the server."""
    poll("run running", lambda: server.run(run_id)["status"] == "running")
    server.kill()


def intact(data_dir: Path) -> None:
    """SQLite's own integrity check passes on the database."""
    with sqlite3.connect(data_dir / "mocapqa.sqlite3") as conn:
        assert conn.execute("PRAGMA integrity_check").fetchone() == ("ok",)


@pytest.mark.slow
def test_a_run_interrupted_by_a_crash_finishes_after_restart(
    tmp_path: Path, cmu_walk: Path
) -> None:
    data_dir = tmp_path / "data"
    take = long_take(cmu_walk, tmp_path)
    server = Server(data_dir)
    try:
        with take.open("rb") as handle:
            created = server.client.post(
                f"{server.url}/api/v1/takes", files={"file": (take.name, handle)}, timeout=300
            ).json()
        run_id = created["run_id"]
        kill_while_running(server, run_id)
        intact(data_dir)
        server = Server(data_dir)
        final = poll("run finished", lambda: server.run(run_id)["status"] in ("done", "failed"))
        assert final
        run = server.run(run_id)
        assert run["status"] == "done", run["error"]
        assert run["attempts"] == 2
        assert server.client.get(f"{server.url}/api/v1/runs/{run_id}/result").is_success
        listed = server.client.get(f"{server.url}/api/v1/takes").json()
        assert [t["id"] for t in listed["items"]] == [created["id"]]
    finally:
        server.stop()
    intact(data_dir)


@pytest.mark.slow
def test_a_run_interrupted_twice_is_failed_with_the_reason(tmp_path: Path, cmu_walk: Path) -> None:
    data_dir = tmp_path / "data"
    take = long_take(cmu_walk, tmp_path)
    server = Server(data_dir)
    try:
        with take.open("rb") as handle:
            created = server.client.post(
                f"{server.url}/api/v1/takes", files={"file": (take.name, handle)}, timeout=300
            ).json()
        run_id = created["run_id"]
        kill_while_running(server, run_id)
        server = Server(data_dir)
        kill_while_running(server, run_id)
        intact(data_dir)
        server = Server(data_dir)
        run = server.run(run_id)
        assert run["status"] == "failed"
        assert run["attempts"] == 2
        assert "stopped during it 2 times" in run["error"]
        # the server is still useful: another run of the same take can be asked for
        again = server.client.post(f"{server.url}/api/v1/takes/{created['id']}/runs", json={})
        assert again.status_code == 201
    finally:
        server.stop()
    intact(data_dir)
