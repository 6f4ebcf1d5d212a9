"""``mocapqa limits build|check|show`` and ``mocapqa bench limits``."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console
from rich.table import Table

from mocapqa.cli.app import bench_app, limits_app
from mocapqa.cli.roles import MappingOption, load_mapping, missing_roles
from mocapqa.errors import InputError

if TYPE_CHECKING:
    from mocapqa.limits.build import BuildParams

__all__ = ["bench_limits", "limits_build", "limits_check", "limits_show"]

console = Console(highlight=False)


def _build_params(
    bin_deg: float | None, dilation: int | None, margin_deg: float | None, paper: bool,
    networks: bool,
) -> BuildParams:  # fmt: skip
    from dataclasses import replace

    from mocapqa.limits.build import DEFAULT_BUILD, PAPER_BUILD

    settings = PAPER_BUILD if paper else DEFAULT_BUILD
    occupancy = settings.occupancy
    if bin_deg is not None:
        occupancy = replace(occupancy, bin_deg=bin_deg)
    if dilation is not None:
        occupancy = replace(occupancy, dilation_bins=dilation)
    if margin_deg is not None:
        occupancy = replace(occupancy, tau_margin_deg=margin_deg)
    settings = replace(settings, occupancy=occupancy)
    if not networks:
        settings = replace(settings, discriminator=None)
    return settings


@limits_app.command("build")
def limits_build(
    corpus_dir: Annotated[Path, typer.Argument(help="Folder searched recursively for BVH takes.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Model file (.npz) to write.")],
    rig: Annotated[
        str | None, typer.Option(help="Rig family to build (cmu, character_creator, bandai).")
    ] = None,
    all_takes: Annotated[
        bool, typer.Option("--all-takes", help="Build on every take, not only the build split.")
    ] = False,
    bin_deg: Annotated[float | None, typer.Option(help="Swing bin size, degrees.")] = None,
    dilation: Annotated[
        int | None, typer.Option(help="Rings of bins added around the map.")
    ] = None,
    margin_deg: Annotated[float | None, typer.Option(help="Twist margin, degrees.")] = None,
    paper: Annotated[
        bool, typer.Option(help="The paper's setting (1° bins, no widening).")
    ] = False,
    networks: Annotated[bool, typer.Option(help="Train the discriminators.")] = True,
) -> None:
    """Build a joint-limits model from a corpus of BVH takes of one rig family."""
    from rich.progress import Progress

    from mocapqa.bench.limits import corpus_rigs
    from mocapqa.limits.build import build_model
    from mocapqa.limits.model import save_model

    settings = _build_params(bin_deg, dilation, margin_deg, paper, networks)
    rigs = corpus_rigs(corpus_dir, (rig,) if rig else None)
    if len(rigs) != 1:
        found = [r.family for r in rigs]
        raise InputError(
            f"Expected takes of exactly one rig family in {corpus_dir} (use --rig), got {found}"
        )
    takes = rigs[0].build + (rigs[0].held_back if all_takes else ())
    with Progress(console=console, transient=True) as progress:
        task = progress.add_task("building joints", total=None)
        n_done = [0]

        def advance(name: str) -> None:
            n_done[0] += 1
            progress.update(task, completed=n_done[0], description=f"built {name}")

        model = build_model([m for _, m in takes], [n for n, _ in takes], settings, advance)
    output.parent.mkdir(parents=True, exist_ok=True)
    save_model(model, output)
    console.print(
        f"wrote {output}: rig {model.rig_family}, {len(model.joints)} joints, "
        f"{len(takes)} takes, {model.n_frames} frames, {output.stat().st_size / 1024:.0f} KiB"
    )


@limits_app.command("check")
def limits_check(
    path: Annotated[Path, typer.Argument(help="BVH take to check.")],
    model_path: Annotated[
        Path | None, typer.Option("--model", help="Limits model; default: the shipped one.")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    network: Annotated[bool, typer.Option(help="Let the discriminator decide.")] = False,
    mapping: MappingOption = None,
) -> None:
    """Check a take against joint limits: share of frames outside and the worst frames.

    A limits model applies to the rig it was built on, matched by joint names and bone axes, so
    ``--mapping`` does not change the check itself; it changes which roles are reported missing
    (the warning line and ``missing_roles`` in the JSON).
    """
    from mocapqa.io.bvh import read_bvh
    from mocapqa.limits.analysis import check_limits
    from mocapqa.limits.model import load_model

    roles = load_mapping(mapping)
    motion = read_bvh(path)
    missing = missing_roles(motion.skeleton, roles)
    model = load_model(model_path) if model_path is not None else None
    report = check_limits(motion, model, method="network" if network else "map")
    data = report.to_json(max_points=0)
    for joint in data["joints"]:
        del joint["frames"]
    data["missing_roles"] = missing
    if as_json:
        print(json.dumps(data, indent=2))
        return
    table = Table(
        title=f"{path.name}: {100 * report.flagged_fraction:.2f} % of frame×joints outside"
    )
    for column in ("joint", "outside %", "max score °", "worst frames (s1, s2, τ)° → score°"):
        table.add_column(column)
    for joint in data["joints"]:
        worst = "; ".join(
            f"{w['frame']}: ({w['s1_deg']:.0f}, {w['s2_deg']:.0f}, {w['tau_deg']:.0f}) → "
            f"{w['score_deg']:.1f}"
            for w in joint["worst_frames"][:3]
        )
        table.add_row(
            joint["name"],
            f"{100 * joint['flagged_fraction']:.2f}",
            f"{joint['max_score_deg']:.1f}",
            worst,
        )
    console.print(table)


@limits_app.command("show")
def limits_show(
    model_path: Annotated[Path, typer.Argument(help="Limits model (.npz).")],
    joint: Annotated[str, typer.Option(help="Joint name or role key, e.g. left_forearm.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="PNG to write.")],
) -> None:
    """Draw one joint's occupancy map and twist bounds as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from mocapqa.limits.model import load_model

    model = load_model(model_path)
    limits = model.joint(joint)
    occupancy = limits.occupancy
    extent = (-180.0, 180.0, -180.0, 180.0)
    figure, axes = plt.subplots(1, 3, figsize=(15, 5), constrained_layout=True)
    panels = (
        ("occupied swing bins", occupancy.occupied.astype(float), "Greys", None),
        ("τ min (°)", np.rad2deg(occupancy.tau_min), "viridis", (-180, 180)),
        ("τ max (°)", np.rad2deg(occupancy.tau_max), "viridis", (-180, 180)),
    )
    for ax, (title, values, cmap, limits_deg) in zip(axes, panels, strict=True):
        image = ax.imshow(
            values.T, origin="lower", extent=extent, cmap=cmap, interpolation="nearest",
            vmin=None if limits_deg is None else limits_deg[0],
            vmax=None if limits_deg is None else limits_deg[1],
        )  # fmt: skip
        ax.set_title(title)
        ax.set_xlabel("s1 (°)")
        ax.set_ylabel("s2 (°)")
        if limits_deg is not None:
            figure.colorbar(image, ax=ax, shrink=0.8)
    figure.suptitle(
        f"{limits.name} ({limits.role}), rig {model.rig_family}: swing–twist limits, "
        f"{occupancy.bin_deg:g}° bins, {limits.n_samples} frames"
    )
    output.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(output, dpi=80)
    plt.close(figure)
    console.print(f"wrote {output}")


def _pct(value: float) -> str:
    return "—" if math.isnan(value) else f"{100 * value:.2f}"


@bench_app.command("limits")
def bench_limits(
    corpus_dir: Annotated[Path, typer.Argument(help="Corpus folder (shared/data).")],
    rig: Annotated[str | None, typer.Option(help="Only this rig family.")] = None,
    networks: Annotated[bool, typer.Option(help="Train and measure the discriminators.")] = True,
    min_offset_deg: Annotated[float, typer.Option(help="Smallest injected offset.")] = 60.0,
    seed: Annotated[int, typer.Option(help="Seed of the injected errors.")] = 0,
    shipped: Annotated[
        bool, typer.Option(help="Measure the shipped models (built on the same split).")
    ] = True,
) -> None:
    """Discriminator accuracy, false flags on held-back takes, injected-error recall, speed."""
    from mocapqa.bench.limits import bench_rig, corpus_rigs
    from mocapqa.limits.model import default_model_paths, load_model

    models = {p.stem: load_model(p) for p in default_model_paths()} if shipped and networks else {}

    settings = _build_params(None, None, None, False, networks)
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
                j.name, _pct(j.accuracy), _pct(j.precision), _pct(j.recall), str(j.hidden_size),
                _pct(j.false_flag_rate),
            )  # fmt: skip
        console.print(table)
        summary.add_row(
            figures.family,
            f"{figures.n_build_takes}/{figures.n_build_frames}",
            f"{figures.n_held_back_takes}/{figures.n_held_back_frames}",
            _pct(figures.false_flag_rate),
            _pct(figures.network_false_flag_rate),
            f"{_pct(figures.injected_flag_rate)} (n={figures.n_injected})",
            f"{figures.lookup_joint_frames_per_s:.3g}",
            f"{figures.map_joint_frames_per_s:.3g}",
            f"{figures.network_joint_frames_per_s:.3g}",
        )
    console.print(summary)
