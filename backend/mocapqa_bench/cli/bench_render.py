"""``mocapqa bench render``: the time of stills, side-by-side images, a GIF and a report."""

from __future__ import annotations

import tempfile
import time
from dataclasses import replace
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from mocapqa.cli.app import bench_app
from mocapqa.cli.render import flagged_at
from mocapqa.cli.report import analyze_take, build_take_report

__all__ = ["bench_render"]

console = Console(highlight=False)


def _long_take(source: Path, n_frames: int, folder: Path) -> Path:
    """A BVH of ``n_frames`` frames made by repeating a real take end to end."""
    from mocapqa.io.bvh import read_bvh
    from mocapqa.io.bvh_write import write_bvh

    motion = read_bvh(source)
    index = np.arange(n_frames) % motion.n_frames
    hint = motion.euler_hint_deg
    longer = replace(
        motion,
        quats=motion.quats[index],
        translations=motion.translations[index],
        euler_hint_deg=None if hint is None else hint[index],
    )
    path = folder / f"{source.stem}_x{n_frames}.bvh"
    write_bvh(path, longer)
    return path


@bench_app.command("render")
def bench_render(
    take: Annotated[Path, typer.Argument(help="A BVH take to draw.")],
    long_take: Annotated[
        Path | None, typer.Option(help="BVH repeated to --report-frames for the report timing.")
    ] = None,
    stills: Annotated[int, typer.Option(help="Stills to time.")] = 10,
    clip_frames: Annotated[int, typer.Option(help="Frames in the timed GIF.")] = 30,
    report_frames: Annotated[int, typer.Option(help="Frames of the timed report's take.")] = 2000,
) -> None:
    """Time stills, side-by-side images, a GIF and a full report; prints a table."""
    from mocapqa.render.service import RenderService

    rows: list[tuple[str, str, str]] = []
    run = analyze_take(take)
    n = run.raw.n_frames
    frames = np.linspace(0, n - 1, stills).round().astype(int)
    with RenderService() as service:
        started = time.perf_counter()
        service.still(run.raw, int(frames[0]))
        rows.append(("first still (VTK start-up)", "1", f"{time.perf_counter() - started:.2f}"))
        started = time.perf_counter()
        for f in frames:
            service.still(run.raw, int(f), flagged_at(run, int(f)))
        per = (time.perf_counter() - started) / len(frames)
        rows.append(("still 640×480, per image", str(len(frames)), f"{per:.3f}"))
        started = time.perf_counter()
        for f in frames:
            service.side_by_side(run.raw, run.corrected, int(f), flagged_at(run, int(f)))
        per = (time.perf_counter() - started) / len(frames)
        rows.append(("raw | corrected 1280×480, per image", str(len(frames)), f"{per:.3f}"))
        started = time.perf_counter()
        service.thumbnail(run.raw)
        rows.append(("thumbnail 192×144", "1", f"{time.perf_counter() - started:.3f}"))
        end = min(n - 1, clip_frames - 1)
        started = time.perf_counter()
        gif = service.clip(run.raw, 0, end, run.corrected, None, "gif")
        rows.append(
            (f"GIF raw | corrected, {end + 1} frames ({len(gif) / 1e3:.0f} kB)", "1",
             f"{time.perf_counter() - started:.2f}")
        )  # fmt: skip
        with tempfile.TemporaryDirectory() as folder:
            source = _long_take(long_take or take, report_frames, Path(folder))
            started = time.perf_counter()
            html = build_take_report(source, service)
            elapsed = time.perf_counter() - started
            external = html.count('src="http') + html.count("src='http")
            rows.append(
                (f"report, {report_frames} frames ({len(html) / 1e6:.1f} MB, "
                 f"{external} external sources)", "1", f"{elapsed:.2f}")
            )  # fmt: skip
    table = Table(title=f"mocapqa bench render · {take.name}")
    table.add_column("what")
    table.add_column("n", justify="right")
    table.add_column("seconds", justify="right")
    for row in rows:
        table.add_row(*row)
    console.print(table)
