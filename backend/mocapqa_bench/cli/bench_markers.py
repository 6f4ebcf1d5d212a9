"""``mocapqa bench markers``: marker QA on real C3D takes.

Swaps injected between neighbouring markers of real takes (precision and recall with the
thresholds chosen leaving each file out; false swaps and spikes per 10,000 frames of the clean
takes; injected-spike recall; check speed of a 10,000-frame, 60-marker take), then gap filling
(gaps of 0.05–2 s injected alone and as occlusions of a segment; fill RMSE in mm per method and
gap length with the fill settings chosen leaving each file out, :mod:`mocapqa_bench.marker_fill`;
the real gapped take against its clean twin and the fill time of a 10,000-frame, 60-marker take,
:mod:`mocapqa_bench.marker_fill_real`). ``--fill-only`` and ``--swaps-only`` run one part.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import typer

from mocapqa.cli.app import bench_app

__all__ = ["bench_markers"]


def _pct(value: Any) -> str:
    return (
        "–" if value is None or not math.isfinite(float(value)) else f"{100 * float(value):.1f} %"
    )


def _swap_tables(figures: dict[str, Any]) -> list[Any]:
    from rich.table import Table

    held = Table(title="Injected swaps, each file held out (thresholds chosen on the others)")
    for column in ("file", "misfit / gain / held", "precision", "recall", "confident P / R",
                   "clean swaps /10k fr", "clean spikes /10k fr"):  # fmt: skip
        held.add_column(column, justify="left" if column == "file" else "right")
    for row in figures["held_out"]:
        every, confident = row["all"], row["confident"]
        held.add_row(
            row["file"], f"{row['swap_misfit']:g} / {row['swap_gain']:g} / {row['swap_held']:g}",
            _pct(every["precision"]), _pct(every["recall"]),
            f"{_pct(confident['precision'])} / {_pct(confident['recall'])}",
            f"{row['clean_swaps_per_10k']:.1f}", f"{row['clean_spikes_per_10k']:.0f}",
        )  # fmt: skip
    chosen = figures["chosen"]
    held.caption = (
        f"chosen on every file: misfit {chosen['swap_misfit']:g}, gain {chosen['swap_gain']:g}, "
        f"held {chosen['swap_held']:g}; "
        f"pooled precision {_pct(chosen['precision'])}, recall {_pct(chosen['recall'])} "
        f"({chosen['injected']} swaps)"
    )
    spikes = Table(title="Injected single-sample spikes: recall by offset (mm)")
    sizes = list(figures["spikes"][0]["recall"]) if figures["spikes"] else []
    spikes.add_column("file")
    for size in sizes:
        spikes.add_column(f"{float(size):g} mm", justify="right")
    for row in figures["spikes"]:
        spikes.add_row(row["file"], *(_pct(row["recall"][size]) for size in sizes))
    speed = figures["speed"]
    spikes.caption = (
        f"check of a {speed['frames']:,}-frame, {speed['markers']}-marker take: "
        f"{speed['wall_s']:.2f} s wall, {speed['cpu_s']:.2f} CPU s (target ≤ 1 s)"
    )
    return [held, spikes]


def _fill_table(rows: list[dict[str, Any]], choices: list[dict[str, Any]]) -> Any:
    from rich.table import Table

    from mocapqa_bench.marker_fill import FILL_CANDIDATES

    table = Table(
        title="Gap fill RMSE (mm) by gap length, each file held out (settings chosen on the "
        "others), gaps where ≥ 3 segment mates stay seen"
    )
    for column in ("gap (s)", "gaps (occl.)", "spline", "rigid", "PCA", "relative PCA", "auto",
                   "auto / spline", "auto / PCA", "chosen"):  # fmt: skip
        table.add_column(column, justify="left" if column in ("gap (s)", "chosen") else "right")
    for row in rows:
        table.add_row(
            row["bin"], f"{row['gaps']} ({row['occlusions']})",
            *(f"{row[f'{m}_mm']:.2f}" for m in ("spline", "rigid", "pca", "relative", "auto")),
            f"{row['auto_vs_spline']:.2f}", f"{row['auto_vs_pca']:.2f}",
            ", ".join(f"{k} {v}" for k, v in row["chosen"].items() if v),
        )  # fmt: skip

    def setting(index: int) -> str:
        chosen = FILL_CANDIDATES[index]
        return f"{chosen.cv_match}, blend {chosen.blend_power:g}"

    held = "; ".join(f"{Path(c['file']).stem}: {setting(c['chosen'])}" for c in choices)
    table.caption = (
        f"targets: auto ≤ 0.5 × spline and ≤ 0.8 × PCA at every length\n"
        f"chosen with each file held out (trial placement, blend power): {held}"
    )
    return table


def _fill_figures(console: Any, corpus: Path, seeds: int, events_per_bin: int) -> None:
    from mocapqa.markers.fill import Apply
    from mocapqa_bench.marker_fill import FILL_CANDIDATES, summarise, tune_leave_one_out
    from mocapqa_bench.marker_fill_real import fill_speed, twin_figures

    with console.status(f"gap fill: {seeds} seeds, {events_per_bin} gaps per bin, each file out"):
        choices, held = tune_leave_one_out(
            corpus, FILL_CANDIDATES, range(seeds), events_per_bin=events_per_bin
        )
    console.print(_fill_table(summarise(held), choices))
    applies: tuple[Apply, ...] = ("confident", "all")
    for apply in applies:
        twin = twin_figures(corpus, apply)
        console.print(
            f"real gapped take (--apply {apply}): {twin['filled_gaps']} of {twin['gaps']} gaps, "
            f"{twin['filled_samples']} samples, RMSE {twin['rmse_mm']:.1f} mm against the clean "
            f"twin, expected {twin['expected_mm']:.1f} mm ({twin['methods']})"
        )
    with console.status("fill time"):
        speed = fill_speed(corpus)
    console.print(
        f"fill of a {speed['frames']:,}-frame, {speed['markers']}-marker take with "
        f"{100 * speed['missing']:.1f} % missing ({speed['gaps']} gaps): {speed['cpu_s']:.1f} "
        f"CPU s, {speed['wall_s']:.1f} s wall"
    )


@bench_app.command("markers")
def bench_markers(
    data: Annotated[Path | None, typer.Option(help="Corpus folder (default: found).")] = None,
    swap_seeds: Annotated[int, typer.Option(help="Seeds of injected swaps per file.")] = 50,
    fill_seeds: Annotated[int, typer.Option(help="Seeds of injected gaps per file.")] = 3,
    events_per_bin: Annotated[
        int, typer.Option(help="Injected gaps per length bin, file and seed.")
    ] = 8,
    swaps_only: Annotated[bool, typer.Option(help="Only the swap and spike figures.")] = False,
    fill_only: Annotated[bool, typer.Option(help="Only the gap-fill figures.")] = False,
) -> None:
    """Swap precision and recall, false swaps and spikes on clean takes, check speed, and
    gap-fill RMSE per method and gap length, on the corpus' real C3D takes."""
    from rich.console import Console

    from mocapqa.corpus import require_corpus
    from mocapqa.errors import InputError

    if swap_seeds < 1 or fill_seeds < 1 or events_per_bin < 1:
        raise InputError("Expected --swap-seeds, --fill-seeds and --events-per-bin ≥ 1")
    corpus = require_corpus(data)
    console = Console()
    if not fill_only:
        from mocapqa_bench.markers import swap_figures

        with console.status(f"swaps: {swap_seeds} seeds per file, each file held out in turn"):
            figures = swap_figures(corpus, range(swap_seeds))
        for table in _swap_tables(figures):
            console.print(table)
    if not swaps_only:
        _fill_figures(console, corpus, fill_seeds, events_per_bin)
