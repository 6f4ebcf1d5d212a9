"""Batch analysis on a real ``distributed.LocalCluster`` (2 worker processes) and on separate
``dask scheduler`` / ``dask worker`` processes, over real corpus takes."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import sqlite3
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cloudpickle
import numpy as np
import pytest
from fastapi.testclient import TestClient

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.jobs.batch import run_batch
from mocapqa.jobs.batch_dask import CHUNK_TAKES, chunk_size
from mocapqa.jobs.engine import WORKER_CONFIG, Engine
from mocapqa.jobs.run_outputs import write_outputs
from mocapqa.jobs.take_task import analyse_path
from mocapqa.limits.catalog import DEFAULT_MODEL
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.loading import read_take_file
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.pipeline.summary import qa_summary
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository
from mocapqa.store.shoots import ShootStore
from mocapqa_bench.batch_client import separate_cluster

TAKES = (
    "bvh/bandai/dataset-1_bow_not-confident_001.bvh",
    "bvh/bandai/dataset-1_bow_sad_001.bvh",
    "bvh/cmu/cmu_12_01_walk.bvh",
    "keypoints/pose2sim/S00_P00_T00_StaticTrial/pose-3d/S00_P00_T00_StaticTrial_0-12.trc",
)
ROOT = Path(__file__).resolve().parents[2]
cloudpickle.register_pickle_by_value(sys.modules[__name__])


@pytest.fixture(scope="module")
def engine() -> Iterator[Engine]:
    """One local cluster of 2 worker processes for the module."""
    with Engine(workers=2) as local:
        local.client()
        yield local


@pytest.fixture
def fresh_engine() -> Iterator[Engine]:
    """A local cluster of 2 worker processes for one test that takes its workers down: whether
    and when Dask's nannies bring a killed worker back is Dask's business, and a cluster left a
    worker short must not slow or stall the tests after it."""
    with Engine(workers=2) as local:
        local.client()
        yield local


@pytest.fixture
def corpus_copy(corpus_dir: Path, tmp_path: Path) -> Path:
    """A folder of links to a few real takes, a corrupted take and a non-motion file."""
    folder = tmp_path / "shoot"
    folder.mkdir()
    for relative in TAKES:
        (folder / Path(relative).name).symlink_to(corpus_dir / relative)
    walk = (corpus_dir / TAKES[2]).read_bytes()
    (folder / "broken.bvh").write_bytes(
        walk[: len(walk) // 2].replace(b"Frames: 524", b"Frames: 600")
    )
    (folder / "notes.txt").write_text("not a take")
    return folder


def _worker_settings() -> tuple[str | None, bool]:
    """What a worker runs with: Dask's malloc trim variable, and whether it profiles."""
    import dask

    return os.environ.get("MALLOC_TRIM_THRESHOLD_"), bool(
        dask.config.get("distributed.worker.profile.enabled")
    )


def test_local_workers_run_with_the_shipped_settings(engine: Engine) -> None:
    """No malloc trim threshold (it costs +40 % CPU a take) and no profiler (+15 %)."""
    found = engine.client().run(_worker_settings)
    assert len(found) == 2
    assert set(found.values()) == {(None, False)}


def _store(tmp_path: Path) -> tuple[Repository, ShootStore]:
    repository = Repository(f"sqlite:///{tmp_path / 'db.sqlite3'}")
    return repository, ShootStore(repository.engine)


def _collect(rows: list[dict[str, Any]]) -> Any:
    return rows.append


def _report_without_timings(path: Path) -> dict[str, Any]:
    report: dict[str, Any] = json.loads(path.read_text())
    report.pop("timings_s", None)
    return report


def test_batch_equals_single_take_analysis(
    engine: Engine, corpus_copy: Path, tmp_path: Path
) -> None:
    repository, shoots = _store(tmp_path)
    data = tmp_path / "data"
    shoot = shoots.create("day")
    rows: list[dict[str, Any]] = []
    counts = run_batch(
        [corpus_copy], shoots, AnalysisOptions(), rows.append, engine, data, str(shoot["id"])
    )
    by_name = {Path(r["source"]).name: r for r in rows}
    assert set(by_name) == {Path(t).name for t in TAKES} | {"broken.bvh"}
    assert (counts.done, counts.failed, counts.skipped) == (4, 1, 0)
    assert "line" in by_name["broken.bvh"]["error"]

    for relative in TAKES:
        row = by_name[Path(relative).name]
        take = read_take_file(corpus_copy / Path(relative).name, "")
        # A batch records the limits model it used: the default one, outside a chosen shoot.
        alone = analyze(take, AnalysisOptions(limits_model=DEFAULT_MODEL))
        expected = qa_summary(alone)
        assert {k: row[k] for k in expected if k != "joint_violations"} == {
            k: v for k, v in expected.items() if k != "joint_violations"
        }
        stored = repository.get_take(row["take_id"])
        run = repository.get_run(str(stored["latest_run_id"]))
        assert run["summary"]["qa"] == expected
        folder = data / "runs" / str(run["id"])
        # The same files as the single-take path writes for this result (the server's).
        alone_store = FileStore(tmp_path / "alone")
        write_outputs(alone_store, str(run["id"]), alone)
        alone_folder = alone_store.run_dir(str(run["id"]))
        report = _report_without_timings(folder / "report.json")
        assert report == _report_without_timings(alone_folder / "report.json")
        with np.load(folder / "points.npz") as points:
            assert np.array_equal(
                points["raw"], alone.raw_points.astype(np.float32), equal_nan=True
            )
            assert np.array_equal(
                points["corrected"], alone.corrected_points.astype(np.float32), equal_nan=True
            )
        assert (data / "takes" / row["take_id"] / Path(relative).name).is_file()
    page, total = shoots.page(str(shoot["id"]))
    assert total == 4

    again: list[dict[str, Any]] = []
    counts = run_batch(
        [corpus_copy], shoots, AnalysisOptions(), again.append, engine, data, str(shoot["id"])
    )
    assert (counts.done, counts.failed, counts.skipped) == (0, 1, 4)
    assert {r["take_id"] for r in again if r["status"] == "skipped"} == {r["take_id"] for r in page}
    assert all(r["score"] is not None for r in again if r["status"] == "skipped")
    assert repository.list_takes()[1] == 4
    other = AnalysisOptions(checks=("twist",))
    counts = run_batch([corpus_copy], shoots, other, again.append, engine, data)
    assert counts.done == 4
    repository.close()


def test_worker_killed_mid_batch(fresh_engine: Engine, corpus_copy: Path, tmp_path: Path) -> None:
    engine = fresh_engine
    repository, shoots = _store(tmp_path)
    client = engine.client()
    pids = client.run(os.getpid)
    rows: list[dict[str, Any]] = []
    killed = threading.Event()

    def on_row(row: dict[str, Any]) -> None:
        rows.append(row)
        if not killed.is_set():
            killed.set()
            os.kill(next(iter(pids.values())), signal.SIGKILL)

    counts = run_batch([corpus_copy], shoots, AnalysisOptions(), on_row, engine, tmp_path / "d")
    assert killed.is_set()
    assert (counts.done, counts.failed) == (4, 1)
    assert repository.list_takes()[1] == 4
    repository.close()


def _dies_on_walk(
    path: str, options: dict[str, Any], take_id: str, run_id: str, data: str | None
) -> dict[str, Any]:
    if path.endswith("cmu_12_01_walk.bvh"):
        os._exit(1)  # a take that takes its worker down
    return analyse_path(path, options, take_id, run_id, data)


def test_take_crashing_two_workers_fails_alone(
    fresh_engine: Engine, corpus_copy: Path, tmp_path: Path
) -> None:
    engine = fresh_engine
    repository, shoots = _store(tmp_path)
    rows: list[dict[str, Any]] = []
    counts = run_batch(
        [corpus_copy], shoots, AnalysisOptions(), rows.append, engine, None, task=_dies_on_walk
    )
    failed = {Path(r["source"]).name: r["error"] for r in rows if r["status"] == "failed"}
    assert set(failed) == {"cmu_12_01_walk.bvh", "broken.bvh"}
    assert "KilledWorker" in failed["cmu_12_01_walk.bvh"]
    assert counts.done == 3
    repository.close()


def _dies_on_walk_raises_on_sad(
    path: str, options: dict[str, Any], take_id: str, run_id: str, data: str | None
) -> dict[str, Any]:
    if path.endswith("bow_sad_001.bvh"):
        raise ValueError("a bug in one take")
    return _dies_on_walk(path, options, take_id, run_id, data)


def test_chunked_tasks_fail_only_the_take_at_fault(
    fresh_engine: Engine, corpus_copy: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Several takes to a task: a take whose task raises fails alone, and a take that kills
    its worker has its chunk sent again one take per task, so only it fails."""
    engine = fresh_engine
    monkeypatch.setattr("mocapqa.jobs.batch_dask.chunk_size", lambda n_pending, in_flight: 3)
    repository, shoots = _store(tmp_path)
    rows: list[dict[str, Any]] = []
    counts = run_batch(
        [corpus_copy], shoots, AnalysisOptions(), rows.append, engine, None,
        task=_dies_on_walk_raises_on_sad,
    )  # fmt: skip
    failed = {Path(r["source"]).name: r["error"] for r in rows if r["status"] == "failed"}
    assert set(failed) == {"cmu_12_01_walk.bvh", "broken.bvh", "dataset-1_bow_sad_001.bvh"}
    assert "KilledWorker" in failed["cmu_12_01_walk.bvh"]
    assert failed["dataset-1_bow_sad_001.bvh"] == "internal error: ValueError: a bug in one take"
    assert counts.done == 2
    assert repository.list_takes()[1] == 2
    repository.close()


def test_chunk_size_keeps_small_batches_one_take_per_task() -> None:
    assert [chunk_size(n, 8) for n in (0, 1, 15, 16, 31, 32, 48, 64, 2000)] == [
        1, 1, 1, 1, 1, 2, 3, 4, 4,
    ]  # fmt: skip
    assert chunk_size(2000, 8) == CHUNK_TAKES


def _environment(tmp_path: Path) -> dict[str, str]:
    return {
        **os.environ,
        "PYTHONPATH": str(ROOT / "backend"),
        "MOCAPQA_DATA_DIR": str(tmp_path / "data"),
    }


def _takes_in(database: Path) -> int:
    if not database.exists():
        return 0
    with sqlite3.connect(database, timeout=30) as conn:
        try:
            return int(conn.execute("SELECT count(*) FROM takes").fetchone()[0])
        except sqlite3.OperationalError:
            return 0


def test_resume_after_the_client_is_killed(corpus_copy: Path, tmp_path: Path) -> None:
    command = [
        sys.executable, "-m", "mocapqa.cli.main", "batch", str(corpus_copy),
        "--workers", "2", "--output", str(tmp_path / "out.jsonl"),
    ]  # fmt: skip
    env = _environment(tmp_path)
    database = tmp_path / "data" / "mocapqa.sqlite3"
    first = subprocess.Popen(command, env=env, start_new_session=True, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while _takes_in(database) < 1 and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    os.killpg(first.pid, signal.SIGKILL)
    first.wait()
    stored_before = _takes_in(database)
    assert stored_before >= 1
    second = subprocess.run(command, env=env, capture_output=True, text=True, timeout=600)
    assert second.returncode == 2, second.stderr  # broken.bvh fails
    rows = [json.loads(line) for line in (tmp_path / "out.jsonl").read_text().splitlines()]
    statuses = [r["status"] for r in rows]
    total = len(rows)
    assert statuses.count("failed") == 1
    assert statuses.count("skipped") >= stored_before
    assert _takes_in(database) == total - 1
    with sqlite3.connect(database) as conn:
        duplicates = conn.execute(
            "SELECT count(*) FROM (SELECT sha256 FROM takes GROUP BY sha256 HAVING count(*) > 1)"
        ).fetchone()[0]
        runs = conn.execute("SELECT count(*) FROM runs WHERE status = 'done'").fetchone()[0]
    assert duplicates == 0
    assert runs == total - 1


@contextlib.contextmanager
def _cluster(tmp_path: Path, blind: bool = False) -> Iterator[str]:
    """A ``dask scheduler`` and a one-process ``dask worker`` with the settings file as the
    image installs it for the compose file's workers (/etc/dask); with ``blind``, the worker
    runs in a mount namespace of its own where ``tmp_path`` (the client's takes and data
    folders) is an empty tmpfs: a worker on another machine, as far as files go. Yields the
    scheduler's address."""
    env = {
        **_environment(tmp_path),
        "DASK_CONFIG": str(ROOT / "backend" / "mocapqa" / WORKER_CONFIG),
    }
    script = 'mount -t tmpfs none "$1" && shift && exec "$@"'
    prefix = ["unshare", "--mount", "--propagation", "private", "sh", "-c", script, "sh",
              str(tmp_path)] if blind else []  # fmt: skip
    with separate_cluster(workers=1, env=env, worker_prefix=prefix) as address:
        yield address


def _server_run(address: str, data_dir: Path, take: Path) -> tuple[dict[str, Any], int]:
    """Upload ``take`` to a server whose runs go to the scheduler at ``address``; the finished
    run and the status code of its result."""
    settings = Settings(allowed_hosts=["testserver"], data_dir=data_dir, dask_scheduler=address)
    with TestClient(create_app(settings)) as client:
        with take.open("rb") as handle:
            created = client.post("/api/v1/takes", files={"file": ("bow.bvh", handle)})
        assert created.status_code == 201, created.text
        run_id = created.json()["run_id"]
        deadline = time.monotonic() + 300
        run: dict[str, Any] = {"status": "queued"}
        while run["status"] not in ("done", "failed") and time.monotonic() < deadline:
            time.sleep(0.2)
            run = client.get(f"/api/v1/runs/{run_id}").json()
        return run, client.get(f"/api/v1/runs/{run_id}/result").status_code


def test_batch_on_separate_scheduler_and_worker(corpus_copy: Path, tmp_path: Path) -> None:
    with _cluster(tmp_path) as address:
        repository, shoots = _store(tmp_path)
        rows: list[dict[str, Any]] = []
        with Engine(scheduler=address) as remote:
            remote.client().wait_for_workers(1, timeout=120)
            assert set(remote.client().run(_worker_settings).values()) == {(None, False)}
            assert remote.shares_disk(corpus_copy / "cmu_12_01_walk.bvh", tmp_path / "d")
            counts = run_batch(
                [corpus_copy], shoots, AnalysisOptions(), rows.append, remote, tmp_path / "d"
            )
        assert (counts.done, counts.failed) == (4, 1)
        assert repository.list_takes()[1] == 4
        repository.close()
        # The server sends its runs to the same cluster when MOCAPQA_DASK_SCHEDULER is set.
        run, result = _server_run(address, tmp_path / "server", corpus_copy / Path(TAKES[0]).name)
        assert run["status"] == "done", run
        assert run["summary"]["qa"]["score"] is not None
        assert result == 200


def test_batch_uses_the_shoot_limits_model(engine: Engine, cmu_walk: Path, tmp_path: Path) -> None:
    """A batch into a shoot checks limits with the shoot's model, resolved in the data folder's
    catalog on the workers, and records it with each run."""
    from mocapqa.limits.catalog import ModelCatalog
    from mocapqa.limits.storage import default_model_paths

    repository, shoots = _store(tmp_path)
    data = tmp_path / "data"
    bandai = next(p for p in default_model_paths() if p.stem == "bandai")
    ModelCatalog.of_data_folder(data).register(bandai, "studio-b")
    shoot = str(shoots.create("Day 3")["id"])
    shoots.set_limits_model(shoot, "studio-b")
    folder = tmp_path / "walks"
    folder.mkdir()
    (folder / cmu_walk.name).symlink_to(cmu_walk)
    rows: list[dict[str, Any]] = []
    counts = run_batch([folder], shoots, AnalysisOptions(), rows.append, engine, data, shoot)
    assert counts.done == 1, rows
    run = repository.list_runs(rows[0]["take_id"])[0]
    assert run["options"]["limits_model"] == "studio-b"
    # Bandai's own model does not cover the CMU skeleton: the check says so, naming the model.
    assert run["summary"]["steps"]["limits"] == "no_model"
    # An explicit model in the options wins over the shoot's.
    counts = run_batch(
        [folder], shoots, AnalysisOptions(limits_model="cmu"), rows.append, engine, data, shoot
    )
    run = repository.list_runs(rows[-1]["take_id"])[-1]
    assert run["options"]["limits_model"] == "cmu"
    assert run["summary"]["steps"]["limits"] == "done"
    repository.close()


def test_batch_and_server_runs_on_a_worker_that_shares_no_disk(
    corpus_copy: Path, tmp_path: Path
) -> None:
    """A worker that sees neither the takes nor the data folder is sent each take's bytes and
    sends the run's files back: every take is done, with the same report as the single-take
    analysis, and the server's runs on that cluster too."""
    with _cluster(tmp_path, blind=True) as address:
        repository, shoots = _store(tmp_path)
        data = tmp_path / "d"
        rows: list[dict[str, Any]] = []
        with Engine(scheduler=address) as remote:
            remote.client().wait_for_workers(1, timeout=120)
            # The worker is blind to the client's folder (what the test is about).
            assert list(remote.client().run(os.path.exists, str(corpus_copy)).values()) == [False]
            assert not remote.shares_disk(corpus_copy / "cmu_12_01_walk.bvh", data)
            counts = run_batch([corpus_copy], shoots, AnalysisOptions(), rows.append, remote, data)
        assert (counts.done, counts.failed) == (4, 1), rows
        for row in (r for r in rows if r["status"] == "done"):
            stored = repository.get_take(row["take_id"])
            run_id = str(stored["latest_run_id"])
            assert (data / "takes" / row["take_id"] / str(stored["file_name"])).is_file()
            assert (data / "takes" / row["take_id"] / ".reading.json").is_file()
            take = read_take_file(corpus_copy / Path(row["source"]).name, "")
            alone = analyze(take, AnalysisOptions(limits_model=DEFAULT_MODEL))
            alone_store = FileStore(tmp_path / "alone")
            write_outputs(alone_store, run_id, alone)
            assert _report_without_timings(
                data / "runs" / run_id / "report.json"
            ) == _report_without_timings(alone_store.run_dir(run_id) / "report.json")
        repository.close()
        run, result = _server_run(address, tmp_path / "server", corpus_copy / Path(TAKES[0]).name)
        assert run["status"] == "done", run
        assert result == 200
        assert (tmp_path / "server" / "runs" / run["id"] / "points.npz").is_file()
