"""``mocapqa bench batch``: batch throughput on Dask against a plain loop, memory, resume time,
and the shoot table's API latency at 10,000 takes."""

from __future__ import annotations

import shutil
import statistics
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from mocapqa.cli.app import bench_app

if TYPE_CHECKING:
    from mocapqa_bench.watch import Watched

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
    from mocapqa.store.stamps import new_id

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


@dataclass
class _Runs:
    """The tiled corpus of one ``mocapqa bench batch``, its scratch folder, and the table of
    rates and the figures its runs fill."""

    root: Path
    tiles: Any
    takes: int
    console: Any
    table: Any
    figures: dict[str, float] = field(default_factory=dict)

    def batch(self, name: str, folder: Path, workers: int, fresh: bool = True) -> Watched:
        """``mocapqa batch`` as its own process, into the database of ``name``."""
        from mocapqa_bench.watch import run_watched

        where = self.root / name
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

    def rate_row(self, label: str, wall: float, cpu: float, client: float, worker: str) -> None:
        """A row of the rates table, printed at once as well."""
        cells = (
            label,
            f"{wall:.1f}",
            f"{cpu:.1f}",
            f"{self.takes / wall:.2f}",
            f"{self.tiles.n_frames / wall:,.0f}",
            f"{client:.0f}",
            worker,
        )
        self.table.add_row(*cells)
        # Each run as it ends too: a run cut short keeps the figures measured before it.
        self.console.print(" | ".join(cells), highlight=False)

    def on_dask(self, one: Path, options: Any) -> list[dict[str, Any]]:
        """``mocapqa batch`` on 2 and 1 workers, each after its start-up on the one tile in
        ``one``, and the resume of the 2-worker batch; the stored rows of that batch."""
        from mocapqa.store.repository import Repository
        from mocapqa_bench.shoot_latency import stored_rows

        figures, takes = self.figures, self.takes
        for workers in (2, 1):
            # Start-up: imports, the local cluster, and one take on cold workers (numba's
            # kernels compiled or loaded, each rig's limits model read): the same command on
            # one tile.
            started = self.batch(f"start{workers}", one, workers)
            run = self.batch(f"dask{workers}", self.tiles.folder, workers)
            repository = Repository(f"sqlite:///{self.root / f'dask{workers}' / 'db.sqlite3'}")
            done = _done_runs(repository)
            if done != takes:
                raise RuntimeError(f"expected {takes} done runs, got {done}")
            figures[f"start{workers}_s"] = started.wall_s
            figures[f"start{workers}_cpu"] = started.cpu_s
            figures[f"dask{workers}_s"] = run.wall_s - started.wall_s
            figures[f"dask{workers}_cpu"] = run.cpu_s - started.cpu_s
            self.console.print(
                f"start-up, one tile: {started.wall_s:.1f} s wall, {started.cpu_s:.1f} CPU s",
                highlight=False,
            )
            label = f"`mocapqa batch --workers {workers}`"
            self.rate_row(label, run.wall_s, run.cpu_s, run.peak_mb, f"{run.children_peak_mb:.0f}")
            if workers == 2:
                self.resume(repository, options)
                rows = stored_rows(repository)
            repository.close()
            # GBs of outputs
            shutil.rmtree(self.root / f"dask{workers}" / "data", ignore_errors=True)
        return rows

    def resume(self, repository: Any, options: Any) -> None:
        """The finished 2-worker batch again: ``mocapqa batch``, and ``run_batch`` alone."""
        from mocapqa.jobs.batch import run_batch
        from mocapqa.store.shoots import ShootStore

        again = self.batch("dask2", self.tiles.folder, 2, fresh=False)
        self.figures["resume_cli_s"] = again.wall_s
        self.figures["resume_peak_mb"] = again.peak_mb
        shoots = ShootStore(repository.engine)
        clock = time.perf_counter()
        counts = run_batch([self.tiles.folder], shoots, options, lambda r: None, None, None)
        self.figures["resume_s"] = time.perf_counter() - clock
        if counts.skipped != self.takes:
            raise RuntimeError(f"resume re-ran takes: {counts}")
        self.console.print(
            f"resume: `mocapqa batch` {again.wall_s:.2f} s wall, {again.cpu_s:.2f} CPU s, "
            f"peak {again.peak_mb:.0f} MB; run_batch alone {self.figures['resume_s']:.2f} s",
            highlight=False,
        )

    def plain_loop(self, warm: list[str], options: Any) -> None:
        """The batch in this process, warmed up on ``warm``, without Dask."""
        from mocapqa.jobs.batch import run_batch
        from mocapqa.store.repository import Repository
        from mocapqa.store.shoots import ShootStore

        folder = self.root / "loop"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        repository = Repository(f"sqlite:///{folder / 'db.sqlite3'}")
        _warm_up(warm, options.to_json())
        with _Sampler() as sampler:
            clock, cpu = time.perf_counter(), time.process_time()
            counts = run_batch(
                [self.tiles.folder],
                ShootStore(repository.engine),
                options,
                lambda r: None,
                None,
                folder / "data",
            )
            self.figures["loop_s"] = time.perf_counter() - clock
            self.figures["loop_cpu"] = time.process_time() - cpu
        repository.close()
        shutil.rmtree(folder / "data", ignore_errors=True)
        if counts.done != self.takes:
            raise RuntimeError(f"expected {self.takes} done, got {counts}")
        self.rate_row(
            "plain loop, one warm process",
            self.figures["loop_s"],
            self.figures["loop_cpu"],
            sampler.peak,
            "–",
        )

    def print_rates(self) -> None:
        """The rates table, the start-up, the Dask overhead and the resume."""
        figures, takes, console = self.figures, self.takes, self.console
        console.print(self.table)
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

    def single_take(self, corpus: Path, warm: list[str], options: Any) -> None:
        """One take here and as a task on a warm Dask worker."""
        from mocapqa.jobs.engine import Engine

        with Engine(workers=1) as engine:
            client = engine.client()
            client.run(_warm_up, warm, options.to_json())
            self.figures.update(
                _single_take(client, corpus, self.root / "single", options.to_json())
            )
        self.console.print(
            f"one take (CMU walk, 524 frames), median of 15: in this process "
            f"{self.figures['single_thread_s'] * 1000:.0f} ms, as a task on a warm Dask worker "
            f"{self.figures['single_dask_s'] * 1000:.0f} ms"
        )


def _warm_takes(root: Path, tiles: Any) -> tuple[list[str], Path]:
    """One tile of each source take (to warm a process up on), and a folder holding the
    first of them alone."""
    by_source: dict[str, str] = {}
    for tile in sorted(tiles.folder.iterdir()):
        by_source.setdefault(tile.stem.split("_", 2)[2], str(tile))
    warm = sorted(by_source.values())
    one = root / "one-take"
    one.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(warm[0], one / Path(warm[0]).name)
    return warm, one


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

    from mocapqa.corpus import require_corpus
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa_bench.batch_client import print_client_figures
    from mocapqa_bench.shoot_latency import api_latency
    from mocapqa_bench.tiles import tile_corpus

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
    warm, one = _warm_takes(root, tiles)
    print_client_figures(console, tiles.folder, warm[0], root)
    if client_only:
        if scratch is None:
            shutil.rmtree(root, ignore_errors=True)
        return
    runs = _Runs(root, tiles, takes, console, table)
    rows = runs.on_dask(one, options)
    runs.plain_loop(warm, options)
    runs.print_rates()
    runs.single_take(corpus, warm, options)
    targets = [("SQLite", f"sqlite:///{root / 'api.sqlite3'}")]
    if postgres_url or os.environ.get("MOCAPQA_TEST_POSTGRES_URL"):
        targets.append(("PostgreSQL", str(postgres_url or os.environ["MOCAPQA_TEST_POSTGRES_URL"])))
    console.print(api_latency(rows, api_takes, targets, root / "api-data"))
    if scratch is None:
        shutil.rmtree(root, ignore_errors=True)
