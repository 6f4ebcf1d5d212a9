"""``mocapqa bench io``: BVH read, read + FK and write throughput over the corpus."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from mocapqa.cli.app import bench_app

if TYPE_CHECKING:
    from rich.console import Console
    from rich.table import Table

    from mocapqa_bench.io import IoBenchParams, Throughput

__all__ = ["bench_io"]


def _time_files(paths: list[Path], repeats: int, console: Console) -> list[Any]:
    """Each file read, read + FK and written ``repeats`` times (after a warm-up of all)."""
    from rich.progress import Progress

    from mocapqa_bench.io import scratch_folder, time_file, warm_up

    timings = []
    with Progress(console=console, transient=True) as progress:
        task = progress.add_task("warming up", total=2 * len(paths))
        for path in paths:
            warm_up([path])
            progress.advance(task)
        with scratch_folder() as scratch:
            for path in paths:
                progress.update(task, description=f"timing {path.name}")
                timings.append(time_file(path, repeats, Path(scratch)))
                progress.advance(task)
    return timings


def _add_throughput(table: Table, row: Throughput, n_files: int) -> None:
    table.add_row(
        row.label, str(n_files), str(row.n_frames), f"{row.n_bytes / 1e6:.2f}",
        f"{row.seconds:.4f}", f"{row.frames_per_s:,.0f}", f"{row.mb_per_s:.1f}",
    )  # fmt: skip


def _compare_table(
    walk: Path, walk_timing: Any, headline: Any, params: IoBenchParams, console: Console
) -> Table:
    """Our reader against pybvh on the CMU walk, and the ``mocapqa info`` process."""
    from rich.table import Table

    from mocapqa_bench.io import Throughput, info_process_time_s

    compare = Table(title=f"Read + joint and End Site positions, {walk.name}", title_justify="left")
    for column in ("reader", "seconds", "frames/s", "MB/s"):
        compare.add_column(column, justify="left" if column == "reader" else "right")
    pair = headline.comparison
    if pair is None:
        console.print("pybvh is not installed (pip install '.[bench]'): no comparison")
    else:
        rows = (
            ("mocapqa", pair.ours_s),
            ("pybvh 0.9", pair.theirs_s),
            ("mocapqa, right after pybvh", pair.ours_first_s),
            ("pybvh 0.9, right after mocapqa", pair.theirs_first_s),
        )
        for name, seconds in rows:
            row = Throughput(name, walk_timing.n_bytes, walk_timing.n_frames, seconds)
            compare.add_row(
                name, f"{seconds:.4f}", f"{row.frames_per_s:,.0f}", f"{row.mb_per_s:.1f}"
            )
        compare.caption = (
            f"pybvh / mocapqa time ratio: {pair.ratio:.2f}× (turns of {params.block_runs} "
            f"runs each); {pair.first_ratio:.2f}× right after the other reader"
        )
    info_s = info_process_time_s(walk, params.info_runs)
    compare.add_row("`mocapqa info` process (cold)", f"{info_s:.3f}", "", "")
    return compare


@bench_app.command("io")
def bench_io(
    data: Annotated[
        Path | None,
        typer.Option(help="Corpus folder (default: $MOCAPQA_CORPUS_DIR or ../shared/data)."),
    ] = None,
    repeats: Annotated[int, typer.Option(help="Timed runs per figure; the best is kept.")] = 3,
    files: Annotated[
        int | None, typer.Option(help="Only the first N BVH files (sorted by path).")
    ] = None,
    info_runs: Annotated[int, typer.Option(help="Runs of the `mocapqa info` process.")] = 5,
    headline_repeats: Annotated[
        int,
        typer.Option(
            help="Timed runs of the largest Bandai read and of each pybvh comparison reader."
        ),
    ] = 100,
    block_runs: Annotated[
        int, typer.Option(help="Consecutive runs per turn of the figures with targets.")
    ] = 10,
) -> None:
    """Read, read + FK and write throughput (frames/s, MB/s); pybvh on the CMU walk."""
    from rich.console import Console
    from rich.table import Table

    from mocapqa.corpus import require_corpus
    from mocapqa.errors import NotFoundError
    from mocapqa_bench.corpus import corpus_bvh_files
    from mocapqa_bench.io import IoBenchParams, Throughput, headline_times, total_throughput

    params = IoBenchParams(
        repeats=repeats,
        max_files=files,
        info_runs=info_runs,
        headline_repeats=headline_repeats,
        block_runs=block_runs,
    )
    root = require_corpus(data)
    paths = corpus_bvh_files(root)
    if not paths:
        raise NotFoundError(f"Expected BVH files under {root}, got none")
    if params.max_files is not None:
        paths = paths[: params.max_files]
    console = Console()
    timings = _time_files(paths, params.repeats, console)
    table = Table(title=f"BVH I/O over {len(paths)} files ({root})", title_justify="left")
    for column in ("measure", "files", "frames", "MB", "seconds", "frames/s", "MB/s"):
        table.add_column(column, justify="left" if column == "measure" else "right")
    for row in total_throughput(timings):
        _add_throughput(table, row, len(timings))
    bandai = [t for t in timings if "bandai" in t.path.parts]
    big = max(bandai, key=lambda t: t.n_bytes) if bandai else None
    walk_timing = next((t for t in timings if t.path.name == "cmu_12_01_walk.bvh"), None)
    walk = walk_timing.path if walk_timing is not None else None
    with console.status("timing the figures with targets, in turns"):
        headline = headline_times(
            walk, big.path if big else None, params.headline_repeats, params.block_runs
        )
    if big is not None and headline.bandai_read_s is not None:
        seconds = headline.bandai_read_s
        largest = Throughput("read, largest Bandai", big.n_bytes, big.n_frames, seconds)
        _add_throughput(table, largest, 1)
        table.caption = f"largest Bandai file: {big.path.name}"
    console.print(table)
    if walk is None or walk_timing is None:
        console.print("CMU walk (cmu_12_01_walk.bvh) not among the files: no pybvh comparison")
        return
    console.print(_compare_table(walk, walk_timing, headline, params, console))
