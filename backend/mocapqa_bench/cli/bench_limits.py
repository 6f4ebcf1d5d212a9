"""``mocapqa bench limits``: the canonical model per rig and left out, the per-rig models."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from mocapqa.cli.app import bench_app
from mocapqa_bench.cli.canonical_figures import pct, print_canonical

__all__ = ["bench_limits"]

console = Console(highlight=False)


@bench_app.command("limits")
def bench_limits(
    corpus_dir: Annotated[Path, typer.Argument(help="Corpus folder (shared/data).")],
    rig: Annotated[str | None, typer.Option(help="Per-rig part: only this rig family.")] = None,
    networks: Annotated[bool, typer.Option(help="Train and measure the discriminators.")] = True,
    min_offset_deg: Annotated[float, typer.Option(help="Smallest injected offset.")] = 60.0,
    seed: Annotated[int, typer.Option(help="Seed of the injected errors.")] = 0,
    shipped: Annotated[
        bool, typer.Option(help="Measure the shipped models (built on the same split).")
    ] = True,
    per_rig: Annotated[
        bool,
        typer.Option(help="Also the per-rig models' own benchmark (networks, speeds)."),
    ] = False,
    joint_margins: Annotated[
        bool,
        typer.Option(
            "--joint-margins",
            help="Only the experiment of per-joint twist margins chosen by nested "
            "leave-one-rig-out (docs/limits.md).",
        ),
    ] = False,
    margin_rule: Annotated[
        str,
        typer.Option(help="--joint-margins: inner false flags averaged ('mean') or worst rig."),
    ] = "mean",
    model_path: Annotated[
        Path | None,
        typer.Option(
            "--model",
            help="Measure this canonical model file instead of the shipped one (built on the "
            "same build takes, e.g. by `mocapqa limits build CORPUS --exclude 005_05.bvh`).",
        ),
    ] = None,
    leave_one_out: Annotated[
        bool,
        typer.Option(
            help="Also the leave-one-rig-out tables (maps built without each rig: they do not "
            "depend on the model measured)."
        ),
    ] = True,
) -> None:
    """Canonical model per rig and leave-one-rig-out; optionally the per-rig models."""
    if joint_margins:
        _bench_joint_margins(corpus_dir, seed, margin_rule)
        return
    print_canonical(corpus_dir, shipped, seed, min_offset_deg, model_path, leave_one_out)
    if per_rig:
        _bench_per_rig(corpus_dir, rig, networks, min_offset_deg, seed, shipped)


def _bench_joint_margins(corpus_dir: Path, seed: int, rule: str) -> None:
    from mocapqa.core.motion import Motion
    from mocapqa.limits.rig import rig_family
    from mocapqa_bench.limits import role_takes
    from mocapqa_bench.limits_margins import nested_margins

    grouped: dict[str, list[tuple[str, Motion]]] = {}
    for name, motion in role_takes(corpus_dir):
        grouped.setdefault(rig_family(motion.skeleton), []).append((name, motion))
    rigs = {family: tuple(takes) for family, takes in grouped.items()}
    results = nested_margins(rigs, seed=seed, rule=rule)
    table = Table(
        title=f"leave one rig out: per-joint twist margins (nested, rule {rule}) vs 40° everywhere"
    )
    for column in (
        "left-out rig", "false flags % (per joint / 40°)", "injected flagged % (per joint / 40°)",
        "margins chosen on the other rigs (°)",
    ):  # fmt: skip
        table.add_column(column)
    for fold in results:
        recall = fold.hits / max(fold.injected, 1)
        uniform = fold.uniform_hits / max(fold.injected, 1)
        table.add_row(
            fold.family,
            f"{pct(fold.false_flags)} / {pct(fold.uniform_false_flags)}",
            f"{pct(recall)} / {pct(uniform)} (n={fold.injected})",
            ", ".join(f"{role} {m:g}" for role, m in fold.margins_deg.items()),
        )
    console.print(table)
    mean = sum(f.false_flags for f in results) / len(results)
    mean_uniform = sum(f.uniform_false_flags for f in results) / len(results)
    console.print(
        f"mean false flags over left-out rigs: {pct(mean)} % (40° everywhere: "
        f"{pct(mean_uniform)} %)"
    )


def _bench_per_rig(
    corpus_dir: Path, rig: str | None, networks: bool, min_offset_deg: float, seed: int,
    shipped: bool,
) -> None:  # fmt: skip

    from dataclasses import replace

    from mocapqa.limits.build import DEFAULT_BUILD
    from mocapqa.limits.storage import default_model_paths, load_model
    from mocapqa_bench.limits import bench_rig, corpus_rigs

    models = {p.stem: load_model(p) for p in default_model_paths()} if shipped and networks else {}
    settings = DEFAULT_BUILD if networks else replace(DEFAULT_BUILD, discriminator=None)
    console.print(
        f"map: bin {settings.occupancy.bin_deg}°, dilation {settings.occupancy.dilation_bins} "
        f"bins, twist margin {settings.occupancy.tau_margin_deg}°, reference {settings.reference}"
    )
    summary = Table(title="limits per rig (held-back takes)")
    for column in (
        "rig", "build takes/frames", "held-back takes/frames", "false flags % (map)",
        "false flags % (net)", f"injected ≥{min_offset_deg:.0f}° flagged %", "lookup jf/s",
        "map check jf/s", "net check jf/s",
    ):  # fmt: skip
        summary.add_column(column)
    for rig_takes in corpus_rigs(corpus_dir, (rig,) if rig else None):
        model = models.get(rig_takes.family)
        if model is not None and model.takes != tuple(n for n, _ in rig_takes.build):
            model = None
        console.print(
            f"{rig_takes.family}: {'shipped model' if model else 'model built now'}, "
            f"{len(rig_takes.build)} build takes, {len(rig_takes.held_back)} held back"
        )
        _, figures = bench_rig(
            rig_takes, settings, seed=seed, min_offset_deg=min_offset_deg, model=model
        )
        table = Table(title=f"{figures.family}: per joint")
        for column in ("joint", "accuracy %", "precision %", "recall %", "hidden", "false flags %"):
            table.add_column(column)
        for j in figures.joints:
            table.add_row(
                j.name, pct(j.accuracy), pct(j.precision), pct(j.recall), str(j.hidden_size),
                pct(j.false_flag_rate),
            )  # fmt: skip
        console.print(table)
        summary.add_row(
            figures.family,
            f"{figures.n_build_takes}/{figures.n_build_frames}",
            f"{figures.n_held_back_takes}/{figures.n_held_back_frames}",
            pct(figures.false_flag_rate),
            pct(figures.network_false_flag_rate),
            f"{pct(figures.injected_flag_rate)} (n={figures.n_injected})",
            f"{figures.lookup_joint_frames_per_s:.3g}",
            f"{figures.map_joint_frames_per_s:.3g}",
            f"{figures.network_joint_frames_per_s:.3g}",
        )
    console.print(summary)
