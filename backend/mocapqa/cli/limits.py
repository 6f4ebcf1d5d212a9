"""``mocapqa limits build|check|show`` (the benchmark: :mod:`mocapqa_bench.cli.bench_limits`)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console
from rich.table import Table

from mocapqa.cli.app import limits_app
from mocapqa.cli.outputs import FolderReads, check_outputs, require_suffix
from mocapqa.cli.reading import read_input_bvh
from mocapqa.cli.roles import MappingOption, load_mapping, missing_roles
from mocapqa.errors import InputError

if TYPE_CHECKING:
    from collections.abc import Callable

    from mocapqa.core.motion import Motion
    from mocapqa.limits.build import BuildParams
    from mocapqa.limits.catalog import ModelCatalog
    from mocapqa.limits.model import LimitsModel

__all__ = ["limits_build", "limits_check", "limits_models", "limits_register", "limits_show"]

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


HiddenOption = Annotated[
    list[int] | None,
    typer.Option(
        help="Hidden units of a network tried per joint (repeatable; default 32 and 16); "
        "the best by validation is kept."
    ),
]
SchedulerOption = Annotated[
    str | None,
    typer.Option(
        help="Read and chart the takes as tasks of this Dask scheduler (tcp://host:8786), "
        "with or without --rig; the maps and networks are trained here."
    ),
]
WorkersOption = Annotated[
    int,
    typer.Option(
        min=0,
        help="Read and chart the takes on a local Dask cluster of N worker processes "
        "(0: in this process, the default).",
    ),
]


@limits_app.command("build")
def limits_build(
    corpus_dir: Annotated[Path, typer.Argument(help="Folder searched recursively for BVH takes.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Model file (.npz) to write.")],
    rig: Annotated[
        str | None,
        typer.Option(
            help="Build a per-rig model of this family (bandai, character_creator, cmu) from "
            "the takes of its one rig in the folder (also with --scheduler/--workers)."
        ),
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
    n_valid: Annotated[
        int | None, typer.Option(help="Valid synthetic samples per joint (default 20000).")
    ] = None,
    exclude: Annotated[
        list[str] | None, typer.Option(help="Take file names to leave out (repeatable).")
    ] = None,
    hidden: HiddenOption = None,
    scheduler: SchedulerOption = None,
    workers: WorkersOption = 0,
    mapping: MappingOption = None,
) -> None:
    """Build a joint-limits model from a folder of BVH takes.

    Without --rig: one rig-independent (canonical) model per role from the takes of every rig
    with roles. With --rig: a model in that rig's own joint frames. --scheduler or --workers
    runs the per-take part of either build on Dask, the training here (same model; worth it
    for folders of hundreds of takes on workers with cores of their own, docs/limits.md).

    ``--mapping`` gives a canonical build the roles of a rig whose joint names are not
    recognised: it applies to the takes whose skeleton has every joint it names (a folder may
    hold other rigs too), and the model stores those roles with the rig's frames, so its takes
    are checked the same way. A per-rig build (--rig) matches joints by name and takes none.
    """
    require_suffix("-o", output, (".npz",), "a limits model")
    check_outputs({"-o": output}, [FolderReads(corpus_dir, (".bvh",), recursive=True), mapping])
    roles = load_mapping(mapping)
    if roles and rig is not None:
        raise InputError(
            f"--mapping {mapping}: a per-rig model (--rig {rig}) matches its joints by name; "
            "leave out --rig for a canonical model that uses the mapping"
        )
    settings = _network_params(
        _build_params(bin_deg, dilation, margin_deg, paper, networks), n_valid, hidden
    )
    left_out = set(exclude or ())
    if scheduler or workers > 0:
        model = _build_on_dask(
            corpus_dir, rig, settings, all_takes, left_out, scheduler, workers, roles
        )
    else:
        model = _build_here(corpus_dir, rig, settings, all_takes, left_out, roles)
    _write_model(model, output)


def _network_params(
    settings: BuildParams, n_valid: int | None, hidden: list[int] | None
) -> BuildParams:
    """``settings`` with the discriminators' sample count and hidden sizes asked for."""
    from dataclasses import replace

    if settings.discriminator is None:
        return settings
    networks = settings.discriminator
    if n_valid is not None:
        networks = replace(networks, n_valid=n_valid)
    if hidden:
        networks = replace(networks, hidden_sizes=tuple(hidden))
    return replace(settings, discriminator=networks)


def _build_here(
    corpus_dir: Path,
    rig: str | None,
    settings: BuildParams,
    all_takes: bool,
    left_out: set[str],
    roles: dict[str, str] | None,
) -> LimitsModel:
    """Read the takes and build the model in this process, with a progress line per joint."""
    from functools import partial

    from rich.progress import Progress

    from mocapqa.core.rig import require_mapped
    from mocapqa.jobs.limits_takes import canonical_takes, rig_takes
    from mocapqa.limits.build import build_canonical_model, build_model

    builder: Callable[..., LimitsModel]
    if rig is None:
        takes = canonical_takes(corpus_dir, all_takes, left_out, roles)
        builder = partial(build_canonical_model, mapping=roles)
    else:
        takes = rig_takes(corpus_dir, rig, all_takes, left_out)
        builder = build_model
    if not takes:
        raise InputError(f"Expected BVH takes with limb roles in {corpus_dir}, got none")
    require_mapped(roles, [m.skeleton for _, m in takes])
    with Progress(console=console, transient=True) as progress:
        task = progress.add_task("building joints", total=None)
        n_done = [0]

        def advance(name: str) -> None:
            n_done[0] += 1
            progress.update(task, completed=n_done[0], description=f"built {name}")
            _log_role(f"built {name}")

        return builder([m for _, m in takes], [n for n, _ in takes], settings, advance)


def _log_role(line: str) -> None:
    """A line per built role when the output is not a terminal (a log file of a long build
    shows no progress bar)."""
    if not console.is_terminal:
        import time

        console.print(f"{time.strftime('%H:%M:%S')} {line}")


def _write_model(model: LimitsModel, output: Path) -> None:
    from mocapqa.io.atomic import write_bytes
    from mocapqa.limits.storage import model_bytes

    output.parent.mkdir(parents=True, exist_ok=True)
    write_bytes(output, model_bytes(model))
    console.print(
        f"wrote {output}: rig {model.rig_family}, {len(model.joints)} joints, "
        f"{len(model.takes)} takes, {model.n_frames} frames, "
        f"{output.stat().st_size / 1024:.0f} KiB"
    )


def _build_on_dask(
    corpus_dir: Path, rig: str | None, settings: BuildParams, all_takes: bool,
    left_out: set[str], scheduler: str | None, workers: int, mapping: dict[str, str] | None,
) -> LimitsModel:  # fmt: skip
    """A canonical (``rig`` None) or per-rig build whose per-take part runs on Dask, with a
    progress bar."""

    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
    )

    from mocapqa.cli.batch import quiet_dask_logging
    from mocapqa.jobs.engine import Engine
    from mocapqa.jobs.limits_build import build_on_engine

    quiet_dask_logging()
    progress = Progress(
        TextColumn("[bold]limits build"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.description}"),
        TimeElapsedColumn(),
        console=console,
        transient=True,
    )
    task = progress.add_task("starting", total=None)

    def step(what: str) -> None:
        progress.update(task, advance=1, description=what)
        if what.startswith("built "):
            _log_role(what)

    with progress, Engine(scheduler, workers or None) as engine:
        return build_on_engine(
            engine,
            corpus_dir,
            settings,
            rig,
            all_takes,
            left_out,
            on_total=lambda total: progress.update(task, total=total),
            step=step,
            mapping=mapping,
        )


@limits_app.command("check")
def limits_check(
    path: Annotated[Path, typer.Argument(help="BVH take to check.")],
    model_path: Annotated[
        str | None,
        typer.Option(
            "--model",
            help="Limits model: a .npz file, or a name of `mocapqa limits models`; default: "
            "the shipped choice for the rig.",
        ),
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    network: Annotated[bool, typer.Option(help="Let the discriminator decide.")] = False,
    mapping: MappingOption = None,
    frame_from: Annotated[
        Path | None,
        typer.Option(
            "--frame-from",
            help="Folder of takes of this take's rig: frame a rig the canonical model has not "
            "seen once from all of them (mostly clean takes), not from this take alone.",
        ),
    ] = None,
) -> None:
    """Check a take against joint limits: share of frames outside and the worst frames.

    With the canonical model (the default for every rig but Character Creator) ``--mapping``
    decides which joints play which role, so it changes the check. A per-rig model matches its
    joints by name and bone axis and ignores it; ``--mapping`` then only changes which roles
    are reported missing (the warning line and ``missing_roles`` in the JSON).

    A rig the canonical model has not seen is framed from the take itself, leaving out the
    frames of the twist intervals the twist detector finds on it (as the pipeline does).
    """
    from mocapqa.io.formats import require_frames
    from mocapqa.limits.analysis import check_limits
    from mocapqa.twist.analysis import analyze_twist

    if frame_from is not None and not frame_from.is_dir():
        what = "a file" if frame_from.exists() else "a path that does not exist"
        raise InputError(f"--frame-from {frame_from}: Expected a folder of BVH takes, got {what}")
    roles = load_mapping(mapping)
    motion = read_input_bvh(path)
    require_frames(motion, path)
    missing = missing_roles(motion.skeleton, roles)
    model = _chosen_model(model_path, motion) if model_path is not None else None
    if frame_from is not None:
        model = _framed_from(motion, model, frame_from, roles)
    try:
        ignore = analyze_twist(motion, mapping=roles, apply="none").interval_frames()
    except InputError:
        ignore = None  # no limb chains to check: nothing to leave out
    report = check_limits(
        motion, model, method="network" if network else "map", mapping=roles, ignore=ignore
    )
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
    for column in ("joint", "role", "outside %", "max score °", "worst frame: read-out"):
        table.add_column(column)
    for joint in data["joints"]:
        worst = joint["worst_frames"][:1]
        table.add_row(
            joint["name"],
            joint["role"],
            f"{100 * joint['flagged_fraction']:.2f}",
            f"{joint['max_score_deg']:.1f}",
            f"{worst[0]['frame']}: {worst[0]['readout']}" if worst else "",
        )
    console.print(table)
    console.print(
        f"model: {report.rig_family} ({report.framing}); not checked "
        f"({len(report.not_checked)}): {', '.join(report.not_checked) or 'none'}"
    )


def _catalog() -> ModelCatalog:
    from mocapqa.config import get_settings
    from mocapqa.limits.catalog import ModelCatalog

    return ModelCatalog.of_data_folder(get_settings().data_dir)


def _chosen_model(value: str, motion: Motion) -> LimitsModel:
    """``--model``: a model file when ``value`` names one, else a name of the catalog."""
    from mocapqa.limits.storage import load_model

    if value.endswith(".npz") or Path(value).is_file():
        return load_model(value)
    return _catalog().load(value, motion.skeleton)


@limits_app.command("models")
def limits_models() -> None:
    """List the limits models a check, a batch or a shoot can name: the default choice, the
    shipped models and those registered in the data folder ($MOCAPQA_DATA_DIR)."""
    table = Table(title="limits models")
    for column in ("name", "kind", "frame", "rig", "takes", "frames"):
        table.add_column(column)
    for entry in _catalog().entries():
        table.add_row(
            entry.name, entry.kind, entry.frame, entry.rig_family,
            str(entry.n_takes), str(entry.n_frames),
        )  # fmt: skip
    console.print(table)


@limits_app.command("register")
def limits_register(
    model_path: Annotated[Path, typer.Argument(help="Model file (.npz) from `limits build`.")],
    name: Annotated[str, typer.Argument(help="Name to choose it by (a-z, 0-9, _ and -).")],
    replace: Annotated[
        bool, typer.Option("--replace", help="Overwrite a model registered under that name.")
    ] = False,
) -> None:
    """Copy a built model into the data folder under NAME, so that an admin can choose it for a
    shoot and `limits check --model NAME` / `batch --options` can name it."""
    entry = _catalog().register(model_path, name, replace)
    console.print(
        f"registered {entry.name}: {entry.frame} model ({entry.rig_family}), "
        f"{entry.n_takes} takes, {entry.n_frames} frames"
    )


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

    from mocapqa.io.atomic import atomic_path
    from mocapqa.limits.storage import load_model

    require_suffix("-o", output, (".png",), "a PNG image")
    check_outputs({"-o": output}, [model_path])
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
    try:
        with atomic_path(output) as temporary:
            figure.savefig(temporary, dpi=80, format="png")
    finally:
        plt.close(figure)
    console.print(f"wrote {output}")


def _framed_from(
    motion: Motion, model: LimitsModel | None, folder: Path, mapping: dict[str, str] | None
) -> LimitsModel:
    """``model`` (default: the shipped one) with the frames of ``motion``'s rig estimated over
    the takes of that rig under ``folder`` (with the roles of ``mapping``)."""
    from mocapqa.limits.build import with_rig_frames
    from mocapqa.limits.canonical import rig_key
    from mocapqa.limits.storage import load_default_model

    model = load_default_model(motion.skeleton) if model is None else model
    if model.frame != "canonical":
        raise InputError(
            f"Expected a canonical limits model with --frame-from, got the {model.rig_family!r} "
            "rig's own model (pass --model with a canonical model)"
        )
    key = rig_key(motion)
    takes = [
        (p.name, m) for p in sorted(folder.rglob("*.bvh")) if rig_key(m := read_input_bvh(p)) == key
    ]
    if not takes:
        raise InputError(f"Expected BVH takes of the checked take's rig under {folder}, got none")
    return with_rig_frames(model, [m for _, m in takes], [n for n, _ in takes], mapping)
