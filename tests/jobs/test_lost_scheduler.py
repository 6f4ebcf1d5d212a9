"""A batch whose ``dask scheduler`` process is killed mid-batch, and a server whose configured
scheduler is gone: both fail with the reason, in bounded time, and nothing is duplicated."""

from __future__ import annotations

import json
import os
import signal
import socket
import sqlite3
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import dask
import distributed  # noqa: F401  (loads its config defaults; see below)
import pytest
from fastapi.testclient import TestClient

from mocapqa.api.app import create_app
from mocapqa.config import Settings

ROOT = Path(__file__).resolve().parents[2]
BANDAI = "bvh/bandai"
TAKES = 12
"""Takes of the batch: enough that a kill after the first stored take lands mid-batch."""
BOUND_S = 300
"""Generous bound on every wait (a loaded 2-core machine)."""


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@pytest.fixture
def shoot_folder(corpus_dir: Path, tmp_path: Path) -> Path:
    """Links to real takes and one corrupted take."""
    folder = tmp_path / "shoot"
    folder.mkdir()
    for path in sorted((corpus_dir / BANDAI).glob("*.bvh"))[:TAKES]:
        (folder / path.name).symlink_to(path)
    walk = (corpus_dir / "bvh/cmu/cmu_12_01_walk.bvh").read_bytes()
    (folder / "broken.bvh").write_bytes(
        walk[: len(walk) // 2].replace(b"Frames: 524", b"Frames: 600")
    )
    return folder


def _environment(tmp_path: Path) -> dict[str, str]:
    return {
        **os.environ,
        "PYTHONPATH": str(ROOT / "backend"),
        "MOCAPQA_DATA_DIR": str(tmp_path / "data"),
        # The client gives up reconnecting after this (Dask's own setting; default 30 s).
        "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "5s",
    }


class Cluster:
    """A ``dask scheduler`` and one ``dask worker`` process on loopback."""

    def __init__(self, port: int, env: dict[str, str]) -> None:
        self.address = f"tcp://127.0.0.1:{port}"
        self.port = port
        self.env = env
        self.dask = str(Path(sys.executable).with_name("dask"))
        self.processes: list[subprocess.Popen[bytes]] = []
        self.scheduler = self._spawn(
            "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"
        )
        self.worker = self._spawn(
            "worker", self.address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"
        )

    def wait_listening(self) -> None:
        """Wait until the scheduler accepts connections."""
        deadline = time.monotonic() + BOUND_S
        while time.monotonic() < deadline:
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                return
            except OSError:
                time.sleep(0.2)
        pytest.fail(f"no scheduler listening at {self.address}")

    def _spawn(self, *arguments: str) -> subprocess.Popen[bytes]:
        process = subprocess.Popen(
            [self.dask, *arguments],
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        self.processes.append(process)
        return process

    def stop(self) -> None:
        for process in self.processes:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in self.processes:
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


@pytest.fixture
def clusters(tmp_path: Path) -> Iterator[list[Cluster]]:
    started: list[Cluster] = []
    yield started
    for cluster in started:
        cluster.stop()


def _count(database: Path, sql: str) -> int:
    if not database.exists():
        return 0
    with sqlite3.connect(database, timeout=30) as conn:
        try:
            return int(conn.execute(sql).fetchone()[0])
        except sqlite3.OperationalError:
            return 0


def _rows(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_lost_scheduler_fails_cleanly_and_resumes(
    shoot_folder: Path, tmp_path: Path, clusters: list[Cluster]
) -> None:
    env = _environment(tmp_path)
    port = _free_port()
    clusters.append(Cluster(port, env))
    address = clusters[0].address
    output = tmp_path / "out.jsonl"
    command = [
        sys.executable, "-m", "mocapqa.cli.main", "batch", str(shoot_folder),
        "--scheduler", address, "--output", str(output),
    ]  # fmt: skip
    database = tmp_path / "data" / "mocapqa.sqlite3"
    first = subprocess.Popen(
        command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    deadline = time.monotonic() + BOUND_S
    takes = "SELECT count(*) FROM takes"
    while _count(database, takes) < 1 and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    assert first.poll() is None, first.communicate()
    os.killpg(clusters[0].scheduler.pid, signal.SIGKILL)
    try:
        _, stderr = first.communicate(timeout=BOUND_S)
    except subprocess.TimeoutExpired:
        first.kill()
        pytest.fail(f"mocapqa batch hung after its scheduler was killed: {first.communicate()}")
    assert first.returncode not in (0, 2), stderr
    assert f"Lost the connection to the Dask scheduler at {address}" in stderr, stderr
    assert "Traceback" not in stderr, stderr
    stored = _count(database, takes)
    assert 1 <= stored < TAKES, "the kill must land mid-batch"
    rows = _rows(output)  # every line is a whole JSON row
    sources = [r["source"] for r in rows]
    assert len(sources) == len(set(sources))
    done = {r["take_id"] for r in rows if r["status"] == "done"}
    assert len(done) == stored  # each stored take has its row, and only those
    assert all(r["status"] != "failed" or Path(r["source"]).name == "broken.bvh" for r in rows)

    clusters[0].stop()
    clusters.append(Cluster(port, env))  # restarted on the same address
    clusters[-1].wait_listening()
    second = subprocess.run(command, env=env, capture_output=True, text=True, timeout=BOUND_S * 2)
    assert second.returncode == 2, second.stderr  # broken.bvh fails
    rows = _rows(output)
    assert sorted(r["source"] for r in rows) == sorted(str(p) for p in shoot_folder.iterdir())
    statuses = [r["status"] for r in rows]
    assert statuses.count("failed") == 1
    assert statuses.count("skipped") == stored
    assert statuses.count("done") == TAKES - stored
    assert _count(database, takes) == TAKES
    assert _count(database, "SELECT count(*) FROM runs WHERE status = 'done'") == TAKES
    assert (
        _count(
            database,
            "SELECT count(*) FROM (SELECT sha256 FROM takes GROUP BY sha256 HAVING count(*) > 1)",
        )
        == 0
    )


def _wait_for_run(client: TestClient, run_id: str) -> dict[str, Any]:
    deadline = time.monotonic() + BOUND_S
    run: dict[str, Any] = {"status": "queued"}
    while run["status"] not in ("done", "failed") and time.monotonic() < deadline:
        time.sleep(0.2)
        run = client.get(f"/api/v1/runs/{run_id}").json()
    return run


def test_server_with_a_gone_scheduler_fails_runs_with_the_reason(
    corpus_dir: Path, tmp_path: Path, clusters: list[Cluster]
) -> None:
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"  # nothing listens there yet
    settings = Settings(
        allowed_hosts=["testserver"], data_dir=tmp_path / "server", dask_scheduler=address
    )
    # distributed is imported above, so its defaults are in the config before this block:
    # leaving the block then restores them, where it would otherwise remove the whole
    # "distributed" section that the first import inside the block had added.
    with (
        dask.config.set({"distributed.comm.timeouts.connect": "2s"}),
        TestClient(create_app(settings)) as client,
    ):
        take = corpus_dir / BANDAI / "dataset-1_bow_sad_001.bvh"
        with take.open("rb") as handle:
            created = client.post("/api/v1/takes", files={"file": ("bow.bvh", handle)})
        assert created.status_code == 201, created.text
        run = _wait_for_run(client, created.json()["run_id"])
        assert run["status"] == "failed", run
        assert f"Expected a Dask scheduler at {address}" in run["error"], run
        # Once the scheduler is there, the next run connects to it: no server restart.
        clusters.append(Cluster(port, _environment(tmp_path)))
        clusters[-1].wait_listening()
        again = client.post(f"/api/v1/takes/{created.json()['id']}/runs")
        assert again.status_code == 201, again.text
        run = _wait_for_run(client, again.json()["id"])
        assert run["status"] == "done", run["error"]
