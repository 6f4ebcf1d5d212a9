"""``mocapqa bench feet``: threshold choice on the fit takes, then recall of injected slides
and penetrations and false skate flags on the held-back takes, and speed
(:mod:`mocapqa.bench.feet`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from mocapqa.cli.app import bench_app

__all__ = ["bench_feet"]


def _share(pair: tuple[int, int]) -> str:
    found, tried = pair
    return f"{found}/{tried}" if tried else "–"


@bench_app.command("feet")
def bench_feet(
    data: Annotated[
        Path | None,
        typer.Option(help="Corpus folder (default: $MOCAPQA_CORPUS_DIR or ../shared/data)."),
    ] = None,
    seed: Annotated[int, typer.Option(help="Seed of the slide directions.")] = 0,
    choose: Annotated[
        bool,
        typer.Option(
            "--choose/--defaults",
            help="Choose the skate parameters on the fit takes (default), or use FeetParams' "
            "defaults as they are.",
        ),
    ] = True,
) -> None:
    """Injected slide and penetration recall, false skate flags per minute, foot-frames/s."""
    from rich.console import Console
    from rich.table import Table

    from mocapqa.bench.feet import (
        CLEAN_FAMILIES,
        DEPTHS_CM,
        MAX_FLAGS_PER_MINUTE,
        SLIDES_CM,
        bench_takes,
        choose_params,
        family_figures,
        feet_speed,
    )
    from mocapqa.corpus import require_corpus
    from mocapqa.feet.params import FeetParams

    console = Console()
    root = require_corpus(data)
    with console.status("reading the corpus"):
        takes = bench_takes(root)
    params = FeetParams()
    if choose:
        with console.status("choosing the skate parameters on the fit takes"):
            choice = choose_params(takes, seed)
        params = choice.params
        grid = Table(
            title=f"Choice on the fit takes (false flags ≤ {MAX_FLAGS_PER_MINUTE}/min on "
            f"{', '.join(CLEAN_FAMILIES)})",
            title_justify="left",
        )
        for column in ("plant_height", "plant_speed", "skate_travel", "recall ≥ 2 cm", "flags/min"):
            grid.add_column(column, justify="right")
        for height, speed, travel, recall, flags in choice.candidates:
            grid.add_row(
                f"{height:g}", f"{speed:g}", f"{travel:g}", f"{recall:.3f}", f"{flags:.2f}"
            )
        grid.caption = f"fit takes: {', '.join(choice.fit_takes)}"
        console.print(grid)
    console.print(
        f"parameters: skate_travel={params.skate_travel:g}, plant_height="
        f"{params.plant_height:g}, plant_speed={params.plant_speed:g} (leg lengths), "
        f"skate_window_s={params.skate_window_s:g}, penetration_depth="
        f"{params.penetration_depth:g}"
    )
    with console.status("injecting slides and penetrations"):
        rows = family_figures(takes, params, seed)
    clean_table = Table(title=f"Clean takes ({root})", title_justify="left")
    for column in ("family", "split", "takes", "minutes", "contacts", "skate/min"):
        clean_table.add_column(column, justify="left" if column in ("family", "split") else "right")
    for row in rows:
        clean_table.add_row(
            row.family + (" (clean)" if row.family in CLEAN_FAMILIES else ""), row.split,
            str(row.takes), f"{row.minutes:.2f}", str(row.contacts),
            f"{row.skate_per_minute:.2f}",
        )  # fmt: skip
    clean_table.caption = "skate/min: skate findings per minute on the takes as they are"
    console.print(clean_table)
    recall_table = Table(title=f"Injected errors found, seed {seed}", title_justify="left")
    recall_table.add_column("injected")
    for row in rows:
        recall_table.add_column(f"{row.family}\n{row.split}", justify="right")
    for size in SLIDES_CM:
        recall_table.add_row(f"slide {size:g} cm", *(_share(r.slide_recall[size]) for r in rows))
    for size in DEPTHS_CM:
        recall_table.add_row(
            f"sink {size:g} cm", *(_share(r.penetration_recall[size]) for r in rows)
        )
    recall_table.add_row("slide error cm", *(f"{r.slide_error_cm:.2f}" for r in rows))
    recall_table.caption = (
        "found/tried; slides over the contact's middle (at most 1 s), sinks over its middle "
        "half (at most 0.5 s) where the foot stands on the floor; slide error: median "
        "|measured − injected| of the slides found"
    )
    console.print(recall_table)
    with console.status("timing"):
        rate = feet_speed(takes, params)
        long_rate = feet_speed(takes, params, concatenate=True)
    console.print(
        f"speed: {rate:,.0f} foot-frames per CPU second over the {len(takes)} takes one by one; "
        f"{long_rate:,.0f} on one long take made of them all"
    )
