"""``mocapqa bench batch``: batch throughput on Dask against a plain loop, memory, resume time,
and the shoot table's API latency at 10,000 takes."""

from __future__ import annotations

import shutil
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Annotated, Any

import typer

from mocapqa.cli.app import bench_app

__all__ = ["bench_batch"]


class _Sampler:
    """Peak resident memory of this process while a block runs (sampled every 50 ms)."""

    def __init__(self) -> None:
        import psutil  # type: ignore[import-untyped]

        self._process = psutil.Process()
        self.peak = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.is_set():
            self.peak = max(self.peak, self._process.memory_info().rss / 2**20)
            self._stop.wait(0.05)

    def __enter__(self) -> _Sampler:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


def _done_runs(repository: Any) -> int:
    from sqlalchemy import func, select

    from mocapqa.store.tables import runs

    with repository.engine.connect() as conn:
        return int(conn.execute(select(func.count()).where(runs.c.status == "done")).scalar_one())


def _single_take(
    client: Any, corpus: Path, folder: Path, options: dict[str, Any], repeats: int = 15
) -> dict[str, float]:
    """Median seconds to analyse and store the CMU walk here and as a task on a warm worker."""
    from mocapqa.jobs.take_task import analyse_path
    from mocapqa.store.repository import new_id

    walk = str(corpus / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    here, remote = [], []
    for _ in range(repeats):
        clock = time.perf_counter()
        analyse_path(walk, options, new_id(), new_id(), str(folder))
        here.append(time.perf_counter() - clock)
        clock = time.perf_counter()
        client.submit(
            analyse_path, walk, options, new_id(), new_id(), str(folder), pure=False
        ).result()
        remote.append(time.perf_counter() - clock)
    return {"single_thread_s": statistics.median(here), "single_dask_s": statistics.median(remote)}


def _warm_up(paths: list[str], options: dict[str, Any]) -> None:
    from mocapqa.jobs.take_task import analyse_path

    for path in paths:
        analyse_path(path, options, "0" * 32, "0" * 32, None)


def _sources(corpus: Path) -> list[Path]:
    # The take with the only real twist errors is for evaluation, never for tuning: left out.
    found = sorted((corpus / "bvh" / "bandai").glob("*.bvh"))
    found += [corpus / "bvh" / "cmu" / "cmu_12_01_walk.bvh"]
    found += [
        p
        for p in sorted((corpus / "bvh" / "cmu" / "iclone").glob("*.bvh"))
        if p.name != "005_05.bvh"
    ]
    return [p for p in found if p.is_file()]


def _latency(client: Any, url: str, params: dict[str, Any], repeats: int) -> tuple[float, float]:
    times = []
    for _ in range(repeats):
        clock = time.perf_counter()
        response = client.get(url, params=params)
        times.append((time.perf_counter() - clock) * 1000)
        if response.status_code != 200:
            raise RuntimeError(f"{url} answered {response.status_code}: {response.text[:200]}")
    times.sort()
    return statistics.median(times), times[min(len(times) - 1, int(0.95 * len(times)))]


def _stored_rows(repository: Any) -> list[dict[str, Any]]:
    """Take values and run summaries of every stored take (to replicate for the API)."""
    from sqlalchemy import select

    from mocapqa.store.tables import runs, takes

    columns = [
        takes.c[name]
        for name in ("format", "kind", "size_bytes", "n_frames", "fps", "n_joints", "file_name")
    ]
    with repository.engine.connect() as conn:
        found = conn.execute(
            select(*columns, runs.c.summary).join(runs, runs.c.take_id == takes.c.id)
        ).mappings()
        return [
            {"take": {k: r[k] for k in r if k != "summary"}, "summary": r["summary"]} for r in found
        ]


def _fill(database_url: str, rows: list[dict[str, Any]], n_takes: int) -> str:
    """A shoot of ``n_takes`` takes whose summaries repeat the batch's real ones."""
    from sqlalchemy import insert

    from mocapqa.store.qa import QA_COLUMNS
    from mocapqa.store.repository import Repository, new_id, utc_now
    from mocapqa.store.shoots import ShootStore
    from mocapqa.store.tables import runs, take_qa, takes
    from mocapqa.store.upgrade import drop_database

    repository = Repository(database_url)
    drop_database(repository.engine)
    repository.close()
    repository = Repository(database_url)
    shoot = ShootStore(repository.engine).create("bench")
    now = utc_now()
    take_rows, run_rows, qa_rows = [], [], []
    for index in range(n_takes):
        source = rows[index % len(rows)]
        take_id, run_id = new_id(), new_id()
        take_rows.append(
            {
                **source["take"],
                "id": take_id,
                "name": f"take_{index:05d}.bvh",
                "sha256": f"{index:064x}",
                "shoot_id": shoot["id"],
                "created_at": now,
            }
        )
        run_rows.append(
            {
                "id": run_id,
                "take_id": take_id,
                "status": "done",
                "progress": 100,
                "step": "done",
                "options": {},
                "input_sha256": f"{index:064x}",
                "version": "bench",
                "summary": source["summary"],
                "created_at": now,
            }
        )
        qa = source["summary"]["qa"]
        qa_rows.append(
            {
                "take_id": take_id,
                "shoot_id": shoot["id"],
                "name": f"take_{index:05d}.bvh",
                "kind": "motion",
                "created_at": now,
                "run_id": run_id,
                "status": "done",
                "review_status": "unreviewed",
                "reviewer": None,
                "n_findings": source["summary"]["n_findings"],
                **{k: qa.get(k) for k in QA_COLUMNS},
            }
        )
    with repository.engine.begin() as conn:
        for table, values in ((takes, take_rows), (runs, run_rows), (take_qa, qa_rows)):
            for start in range(0, len(values), 1000):
                conn.execute(insert(table), values[start : start + 1000])
    repository.close()
    return str(shoot["id"])


def api_latency(
    rows: list[dict[str, Any]], n_takes: int, targets: list[tuple[str, str]], data_dir: Path
) -> Any:
    """The shoot view's requests on a shoot of ``n_takes`` takes repeating ``rows`` (stored
    take values and summaries), through the app, on each ``(label, database URL)``: a table
    of p50 / p95 ms over 40 requests after 3 warm-ups."""
    from fastapi.testclient import TestClient
    from rich.table import Table

    from mocapqa.api.app import create_app
    from mocapqa.config import Settings

    latency = Table("database", "request", "p50 ms", "p95 ms")
    for label, url in targets:
        shoot_id = _fill(url, rows, n_takes)
        settings = Settings(data_dir=data_dir, database_url=url, allowed_hosts=["testserver"])
        with TestClient(create_app(settings)) as client:
            base = f"/api/v1/shoots/{shoot_id}"
            filtered = {"sort": "violation_share", "order": "desc", "min_score": 50}
            requests: tuple[tuple[str, str, dict[str, Any]], ...] = (
                ("list page (50, by created_at)", f"{base}/takes", {"sort": "created_at"}),
                ("sort by score", f"{base}/takes", {"sort": "score", "offset": 5000}),
                ("filter + search", f"{base}/takes", {**filtered, "search": "take_01"}),
                ("heat map (200 takes)", f"{base}/heatmap", {}),
                ("heat map, filtered and sorted", f"{base}/heatmap", filtered),
                ("next for review", f"{base}/next", {}),
                ("shoot list", "/api/v1/shoots", {}),
            )
            for name, path, params in requests:
                _latency(client, path, params, 3)
                p50, p95 = _latency(client, path, params, 40)
                latency.add_row(label, name, f"{p50:.1f}", f"{p95:.1f}")
    return latency


def _client_cost(folder: Path, summary: dict[str, Any], scratch: Path, engine: Any = None) -> Any:
    """Run a batch of ``folder`` with :func:`empty_analysis` into a new SQLite store.

    Parameters
    ----------
    folder : Path
        The takes (hashed and stored as a real batch would).
    summary : dict
        The run summary every take gets.
    scratch : Path
        A new folder for the store.
    engine : Engine, optional
        A Dask engine (its local cluster's scheduler runs in this process, so its CPU is
        counted); None runs the empty tasks in this process.
    """
    import functools

    from mocapqa.bench.batch_client import ClientCost, empty_analysis
    from mocapqa.jobs.batch import run_batch
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore

    scratch.mkdir(parents=True, exist_ok=True)
    repository = Repository(f"sqlite:///{scratch / 'db.sqlite3'}")
    task = functools.partial(empty_analysis, summary)
    try:
        clock, cpu = time.perf_counter(), time.process_time()
        counts = run_batch(
            [folder], ShootStore(repository.engine), AnalysisOptions(), lambda row: None,
            engine, None, task=task,
        )  # fmt: skip
        return ClientCost(counts.done, time.process_time() - cpu, time.perf_counter() - clock)
    finally:
        repository.close()


def _client_figures(console: Any, folder: Path, sample: str, root: Path) -> None:
    """Print the client's CPU per take with an empty analysis, alone and on 2 Dask workers."""
    from mocapqa.bench.batch_client import separate_cluster
    from mocapqa.jobs.engine import Engine
    from mocapqa.jobs.take_task import analyse_path, content_sha256
    from mocapqa.pipeline.options import AnalysisOptions

    summary = analyse_path(sample, AnalysisOptions().to_json(), "0" * 32, "1" * 32, None)
    alone = _client_cost(folder, summary["summary"], root / "client-alone")
    with separate_cluster(workers=2) as address, Engine(scheduler=address) as engine:
        engine.client().wait_for_workers(2, timeout=120)
        on_dask = _client_cost(folder, summary["summary"], root / "client-dask", engine)
    cpu = time.process_time()
    for path in sorted(folder.iterdir()):
        content_sha256(path)
    hashing_ms = 1000 * (time.process_time() - cpu) / max(1, alone.takes)
    console.print(
        f"client CPU per take, empty analysis ({alone.takes} takes; hash, store, row; of which "
        f"hashing the take's bytes {hashing_ms:.2f} ms): "
        f"tasks in the client's process {alone.cpu_ms_per_take:.2f} ms; sent to 2 Dask "
        f"workers (scheduler and workers in processes of their own) "
        f"{on_dask.cpu_ms_per_take:.2f} ms (target ≤ 1 ms)",
        highlight=False,
    )


@bench_app.command("batch")
def bench_batch(
    takes: Annotated[int, typer.Option(help="Tiled takes in the corpus.")] = 2000,
    mean_frames: Annotated[int, typer.Option(help="Mean frames per tiled take.")] = 520,
    seed: Annotated[int, typer.Option(help="Seed of the tiling.")] = 0,
    api_takes: Annotated[
        int, typer.Option(help="Takes of the shoot for the API figures.")
    ] = 10_000,
    postgres_url: Annotated[
        str | None, typer.Option(help="Also time the API on this PostgreSQL (emptied first).")
    ] = None,
    data: Annotated[Path | None, typer.Option(help="Corpus folder (default: found).")] = None,
    scratch: Annotated[
        Path | None, typer.Option(help="Scratch folder (default: temporary).")
    ] = None,
    client_only: Annotated[
        bool, typer.Option(help="Measure only the client's CPU per take (empty analysis).")
    ] = False,
) -> None:
    """Takes/s and frames/s on 1 and 2 Dask workers and in a plain loop; memory; resume time;
    the client's CPU per take with an empty analysis; shoot-table API latency (list, sort by
    score, heat map) at ``--api-takes`` takes."""
    import os

    from rich.console import Console
    from rich.table import Table

    from mocapqa.bench.tiles import tile_corpus
    from mocapqa.bench.watch import Watched, run_watched
    from mocapqa.corpus import require_corpus
    from mocapqa.jobs.batch import run_batch
    from mocapqa.jobs.engine import Engine
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore

    console = Console()
    root = Path(scratch) if scratch else Path(tempfile.mkdtemp(prefix="mocapqa-bench-batch-"))
    corpus = require_corpus(data)
    clock = time.perf_counter()
    tiles = tile_corpus(_sources(corpus), root / "tiles", takes, mean_frames, seed)
    console.print(
        f"corpus: {tiles.n_takes} takes, {tiles.n_frames:,} frames, "
        f"{tiles.n_bytes / 1e6:,.0f} MB in {time.perf_counter() - clock:.1f} s ({root})"
    )
    options = AnalysisOptions()
    table = Table(
        "run", "wall s", "CPU s", "takes/s", "frames/s", "client peak MB", "worker peak MB"
    )
    figures: dict[str, float] = {}
    by_source: dict[str, str] = {}
    for tile in sorted(tiles.folder.iterdir()):
        by_source.setdefault(tile.stem.split("_", 2)[2], str(tile))
    warm = sorted(by_source.values())
    one = root / "one-take"
    one.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(warm[0], one / Path(warm[0]).name)
    _client_figures(console, tiles.folder, warm[0], root)
    if client_only:
        if scratch is None:
            shutil.rmtree(root, ignore_errors=True)
        return

    def batch(name: str, folder: Path, workers: int, fresh: bool = True) -> Watched:
        """``mocapqa batch`` as its own process, into the database of ``name``."""
        where = root / name
        if fresh:
            shutil.rmtree(where, ignore_errors=True)
        where.mkdir(parents=True, exist_ok=True)
        env = {
            "MOCAPQA_DATA_DIR": str(where / "data"),
            "MOCAPQA_DATABASE_URL": f"sqlite:///{where / 'db.sqlite3'}",
            "MOCAPQA_DASK_SCHEDULER": "",
        }
        command = [sys.executable, "-m", "mocapqa.cli.main", "batch", str(folder)]
        command += ["--workers", str(workers), "--output", str(where / "results.jsonl")]
        watched = run_watched(command, env)
        if watched.returncode != 0:
            raise RuntimeError(f"mocapqa batch exited {watched.returncode}: {watched.stderr}")
        return watched

    def rate_row(label: str, wall: float, cpu: float, client: float, worker: str) -> None:
        cells = (
            label,
            f"{wall:.1f}",
            f"{cpu:.1f}",
            f"{takes / wall:.2f}",
            f"{tiles.n_frames / wall:,.0f}",
            f"{client:.0f}",
            worker,
        )
        table.add_row(*cells)
        # Each run as it ends too: a run cut short keeps the figures measured before it.
        console.print(" | ".join(cells), highlight=False)

    for workers in (2, 1):
        # Start-up: imports, the local cluster, and one take on cold workers (numba's kernels
        # compiled or loaded, each rig's limits model read): the same command on one tile.
        started = batch(f"start{workers}", one, workers)
        run = batch(f"dask{workers}", tiles.folder, workers)
        repository = Repository(f"sqlite:///{root / f'dask{workers}' / 'db.sqlite3'}")
        done = _done_runs(repository)
        if done != takes:
            raise RuntimeError(f"expected {takes} done runs, got {done}")
        figures[f"start{workers}_s"], figures[f"start{workers}_cpu"] = started.wall_s, started.cpu_s
        figures[f"dask{workers}_s"] = run.wall_s - started.wall_s
        figures[f"dask{workers}_cpu"] = run.cpu_s - started.cpu_s
        console.print(
            f"start-up, one tile: {started.wall_s:.1f} s wall, {started.cpu_s:.1f} CPU s",
            highlight=False,
        )
        label = f"`mocapqa batch --workers {workers}`"
        rate_row(label, run.wall_s, run.cpu_s, run.peak_mb, f"{run.children_peak_mb:.0f}")
        if workers == 2:
            again = batch("dask2", tiles.folder, workers, fresh=False)
            figures["resume_cli_s"] = again.wall_s
            figures["resume_peak_mb"] = again.peak_mb
            shoots = ShootStore(repository.engine)
            clock = time.perf_counter()
            counts = run_batch([tiles.folder], shoots, options, lambda r: None, None, None)
            figures["resume_s"] = time.perf_counter() - clock
            if counts.skipped != takes:
                raise RuntimeError(f"resume re-ran takes: {counts}")
            console.print(
                f"resume: `mocapqa batch` {again.wall_s:.2f} s wall, {again.cpu_s:.2f} CPU s, "
                f"peak {again.peak_mb:.0f} MB; run_batch alone {figures['resume_s']:.2f} s",
                highlight=False,
            )
            rows = _stored_rows(repository)
        repository.close()
        shutil.rmtree(root / f"dask{workers}" / "data", ignore_errors=True)  # GBs of outputs

    folder = root / "loop"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    repository = Repository(f"sqlite:///{folder / 'db.sqlite3'}")
    _warm_up(warm, options.to_json())
    with _Sampler() as sampler:
        clock, cpu = time.perf_counter(), time.process_time()
        counts = run_batch(
            [tiles.folder],
            ShootStore(repository.engine),
            options,
            lambda r: None,
            None,
            folder / "data",
        )
        figures["loop_s"] = time.perf_counter() - clock
        figures["loop_cpu"] = time.process_time() - cpu
    repository.close()
    shutil.rmtree(folder / "data", ignore_errors=True)
    if counts.done != takes:
        raise RuntimeError(f"expected {takes} done, got {counts}")
    rate_row(
        "plain loop, one warm process", figures["loop_s"], figures["loop_cpu"], sampler.peak, "–"
    )
    console.print(table)
    for workers in (1, 2):
        console.print(
            f"start-up of `mocapqa batch --workers {workers}` (one tile, cold workers): "
            f"{figures[f'start{workers}_s']:.1f} s wall, {figures[f'start{workers}_cpu']:.1f} "
            f"CPU s; the {takes} takes without it: {figures[f'dask{workers}_s']:.1f} s wall, "
            f"{figures[f'dask{workers}_cpu']:.1f} CPU s "
            f"({takes / figures[f'dask{workers}_s']:.2f} takes/s)"
        )
    console.print(
        f"Dask overhead, 1 worker vs the loop, start-up left out: wall "
        f"{figures['dask1_s'] / figures['loop_s'] - 1:+.1%}, CPU "
        f"{figures['dask1_cpu'] / figures['loop_cpu'] - 1:+.1%} (target ≤ 15 %); "
        f"2 workers / 1 worker speed-up: {figures['dask1_s'] / figures['dask2_s']:.2f}×"
    )
    console.print(
        f"resume of the finished batch: `mocapqa batch` {figures['resume_cli_s']:.2f} s "
        f"(process start and imports included; peak {figures['resume_peak_mb']:.0f} MB), "
        f"run_batch alone {figures['resume_s']:.2f} s (target ≤ 5 s)"
    )
    with Engine(workers=1) as engine:
        client = engine.client()
        client.run(_warm_up, warm, options.to_json())
        figures.update(_single_take(client, corpus, root / "single", options.to_json()))
    console.print(
        f"one take (CMU walk, 524 frames), median of 15: in this process "
        f"{figures['single_thread_s'] * 1000:.0f} ms, as a task on a warm Dask worker "
        f"{figures['single_dask_s'] * 1000:.0f} ms"
    )
    targets = [("SQLite", f"sqlite:///{root / 'api.sqlite3'}")]
    if postgres_url or os.environ.get("MOCAPQA_TEST_POSTGRES_URL"):
        targets.append(("PostgreSQL", str(postgres_url or os.environ["MOCAPQA_TEST_POSTGRES_URL"])))
    console.print(api_latency(rows, api_takes, targets, root / "api-data"))
    if scratch is None:
        shutil.rmtree(root, ignore_errors=True)
