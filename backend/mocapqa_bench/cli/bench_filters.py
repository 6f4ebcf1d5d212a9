"""``mocapqa bench filters``: keypoint and rotation filters on real takes with seeded noise."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from mocapqa.cli.app import bench_app
from mocapqa.errors import InputError

__all__ = ["bench_filters"]

console = Console(highlight=False)


def _table(title: str, rows: list[dict[str, Any]]) -> Table:
    table = Table(title=title)
    if not rows:
        return table
    keys = list(dict.fromkeys(k for r in rows for k in r))
    for k in keys:
        table.add_column(k)
    for r in rows:
        table.add_row(*(_fmt(r.get(k, "")) for k in keys))
    return table


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if hasattr(value, "tolist"):
        return " ".join(f"{v:.3g}" for v in value.tolist())
    return str(value)


@bench_app.command("filters")
def bench_filters(
    data: Annotated[Path | None, typer.Option(help="Corpus folder (shared/data).")] = None,
    seed: Annotated[int, typer.Option(help="Noise seed.")] = 0,
    limit: Annotated[int | None, typer.Option(help="Use only the first N takes.")] = None,
) -> None:
    """Keypoint and rotation filters on real takes with seeded noise; prints tables."""
    from mocapqa.corpus import require_corpus
    from mocapqa_bench.filters import (
        keypoint_cases,
        keypoint_table,
        load_takes,
        note_table,
        pose2sim_table,
        speed_table,
        split_takes,
    )
    from mocapqa_bench.rotation_filters import (
        clean_change_table,
        quamo_table,
        rotation_cases,
        rotation_table,
        tune_quat_pd,
    )

    root = require_corpus(data)
    if not (root / "bvh" / "bandai").is_dir():
        raise InputError(f"Expected a corpus folder with bvh/bandai (--data), got {root}")
    train, test = split_takes(load_takes(root, limit))
    console.print(f"Bandai takes: {len(train)} training, {len(test)} test; seed {seed}")
    k_train, k_test = keypoint_cases(train, seed), keypoint_cases(test, seed)
    console.print(_table("Keypoints (cm; test takes)", keypoint_table(k_train, k_test)))
    console.print(_table("The note's table (note preset; test takes)", note_table(k_test)))
    r_train, r_test = rotation_cases(train, seed), rotation_cases(test, seed)
    tuned = tune_quat_pd(r_train)
    console.print(_table("Rotations (test takes)", rotation_table(r_test, tuned)))
    console.print(_table("QuaMo ablation (tuned gains; test takes)", quamo_table(r_test, tuned)))
    console.print(
        _table(
            "Rotation filters on the test takes as recorded (no noise)", clean_change_table(test)
        )
    )
    console.print(_table("Pose2Sim raw TRC vs its Butterworth file", pose2sim_table(root)))
    console.print(_table("Speed", speed_table()))
