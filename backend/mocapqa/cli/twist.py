"""``mocapqa refine``, ``mocapqa detect`` and ``mocapqa bench twist``: axial twist errors."""

from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.progress import Progress
from rich.table import Table

from mocapqa.cli.app import app, bench_app
from mocapqa.cli.roles import MappingOption, load_mapping, missing_roles

if TYPE_CHECKING:
    from mocapqa.twist.analysis import TwistAnalysis

__all__ = ["bench_twist", "detect", "refine"]

_METHOD_HELP = "Detector: robust (default) or paper (the published rule as written)."


def _report(analysis: TwistAnalysis, path: Path, missing: list[str]) -> dict[str, Any]:
    return {
        "input": str(path),
        "method": analysis.method,
        "missing_roles": missing,
        "n_frames": analysis.refined.n_frames,
        "fps": analysis.fps,
        "intervals": [i.to_json() for i in analysis.intervals],
        "joints": analysis.summaries(),
    }


def _check_method(method: str) -> None:
    from mocapqa.errors import InputError
    from mocapqa.twist.analysis import METHODS

    if method not in METHODS:
        raise InputError(f"Expected --method in {METHODS}, got {method!r}")


@app.command()
def refine(
    input_path: Annotated[Path, typer.Argument(metavar="IN.bvh", help="Take to refine.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Refined BVH to write.")],
    method: Annotated[str, typer.Option(help=_METHOD_HELP)] = "robust",
    report: Annotated[
        Path | None, typer.Option(help="Write the intervals and per-joint summaries as JSON.")
    ] = None,
    mapping: MappingOption = None,
) -> None:
    """Remove axial twist errors; writes the take with the input's layout and frame time."""
    from mocapqa.io.bvh import read_bvh
    from mocapqa.io.bvh_write import write_bvh
    from mocapqa.twist.analysis import analyze_twist

    _check_method(method)
    roles = load_mapping(mapping)
    motion = read_bvh(input_path)
    missing = missing_roles(motion.skeleton, roles)
    analysis = analyze_twist(motion, method, roles)
    write_bvh(output, analysis.refined)
    if report is not None:
        text = json.dumps(_report(analysis, input_path, missing), indent=2)
        report.write_text(text, encoding="utf-8")
    console = Console(highlight=False)
    frames = sum(i.end_frame - i.start_frame + 1 for i in analysis.intervals)
    console.print(
        f"{len(analysis.intervals)} intervals ({frames} joint frames) corrected → {output}"
    )


@app.command()
def detect(
    input_path: Annotated[Path, typer.Argument(metavar="IN.bvh", help="Take to check.")],
    method: Annotated[str, typer.Option(help=_METHOD_HELP)] = "robust",
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
    mapping: MappingOption = None,
) -> None:
    """Report axial twist error intervals without writing anything."""
    from mocapqa.io.bvh import read_bvh
    from mocapqa.twist.analysis import analyze_twist

    _check_method(method)
    roles = load_mapping(mapping)
    motion = read_bvh(input_path)
    missing = missing_roles(motion.skeleton, roles)
    analysis = analyze_twist(motion, method, roles)
    if as_json:
        typer.echo(json.dumps(_report(analysis, input_path, missing), indent=2))
        return
    table = Table(title=f"Twist intervals ({method}) in {input_path.name}")
    for column in ("joint", "start", "end", "offset °", "confidence"):
        table.add_column(column, justify="left" if column == "joint" else "right")
    for i in analysis.intervals:
        table.add_row(
            i.joint,
            str(i.start_frame),
            str(i.end_frame),
            f"{i.offset_deg:.1f}",
            f"{i.confidence:.2f}",
        )
    Console(highlight=False).print(table)


def _default_corpus() -> Path:
    """``$MOCAPQA_CORPUS_DIR/bvh``, else ``../shared/data/bvh`` from the working folder."""
    root = os.environ.get("MOCAPQA_CORPUS_DIR")
    return (Path(root) if root else Path.cwd().parent / "shared" / "data") / "bvh"


def _ablations() -> dict[str, tuple[str, Any]]:
    from mocapqa.twist.detect import RobustParams

    base = RobustParams()
    return {
        "all ideas (= robust)": ("robust", base),
        "θP from swing–twist angle": ("robust", replace(base, parent_source="swing_twist")),
        "θC from azimuth (paper)": ("robust", replace(base, child_source="azimuth")),
        "θC azimuth where conditioned": ("robust", replace(base, child_source="auto")),
        "no onset/release pairing": ("robust", replace(base, pair_events=False)),
        "no noise scaling (2° floor)": ("robust", replace(base, noise_factor=0.0)),
        "sign test, not modulo 360°": ("robust", replace(base, modular=False)),
        "one pass": ("robust", replace(base, passes=1)),
        "consistency 0.35": ("robust", replace(base, consistency=0.35)),
    }


_SEGMENTS = ("clavicle", "upper_arm", "forearm", "upper_leg", "lower_leg")


def _table1(methods: dict[str, Any]) -> Table:
    from mocapqa.bench.twist import RIGS

    groups: list[tuple[str, tuple[str, ...], bool | None]] = [
        *[(rig, (rig,), None) for rig in RIGS],
        ("all", RIGS, None),
        ("all: fit set", RIGS, False),
        ("all: held-out", RIGS, True),
    ]
    table = Table(title="Table 1: rotation error of the target joints on the error frames")
    for column in ("set", "method", "frames", "MAE before °", "MAE after °", "RMSE before °",
                   "RMSE after °", "FSR %", "clean >1° %", "clean max °", "frames/s"):  # fmt: skip
        table.add_column(column, justify="left" if column in ("set", "method") else "right")
    for name, rigs, held in groups:
        for label, res in methods.items():
            acc = res.accuracy(rigs, held)
            clean = res.clean_figure(rigs, held)
            table.add_row(
                name, label, str(acc.n_frames), f"{acc.mae_before_deg:.2f}",
                f"{acc.mae_after_deg:.2f}", f"{acc.rmse_before_deg:.2f}",
                f"{acc.rmse_after_deg:.2f}", f"{100 * acc.fsr:.2f}", f"{100 * clean.share:.4f}",
                f"{clean.max_change_deg:.1f}",
                "" if held is not None else f"{res.speed(rigs):,.0f}",
            )  # fmt: skip
    return table


def _table2(label: str, res: Any) -> Table:
    from mocapqa.bench.twist import RIGS

    table = Table(title=f"Table 2 ({label}): per side × segment — MAE after ° / RER / FSR %")
    table.add_column("segment")
    table.add_column("side")
    sets = [("all", RIGS), *[(rig, (rig,)) for rig in RIGS]]
    for name, _ in sets:
        table.add_column(name, justify="right")
    for segment in _SEGMENTS:
        for side in ("left", "right"):
            cells = []
            for _, rigs in sets:
                acc = res.accuracy(rigs, None, side, segment)
                cells.append(
                    f"{acc.mae_after_deg:.2f} / {acc.rer:.3f} / {100 * acc.fsr:.1f}"
                    if acc.n_frames
                    else "–"
                )
            table.add_row(segment, side, *cells)
    return table


def _ablation_table(methods: dict[str, Any]) -> Table:
    table = Table(title="Ablation (all rigs): the robust method with one idea changed")
    for column in ("variant", "FSR %", "fit FSR %", "held-out FSR %", "worst side×segment FSR %",
                   "MAE after °", "RMSE after °", "clean >1° %", "clean max °"):  # fmt: skip
        table.add_column(column, justify="left" if column == "variant" else "right")
    for label, res in methods.items():
        acc = res.accuracy()
        per_segment = [
            res.accuracy(side=side, segment=segment)
            for side in ("left", "right")
            for segment in _SEGMENTS
        ]
        worst = min((100 * a.fsr for a in per_segment if a.n_frames), default=float("nan"))
        clean = res.clean_figure()
        table.add_row(
            label, f"{100 * acc.fsr:.2f}", f"{100 * res.accuracy(held_out=False).fsr:.2f}",
            f"{100 * res.accuracy(held_out=True).fsr:.2f}", f"{worst:.1f}",
            f"{acc.mae_after_deg:.2f}", f"{acc.rmse_after_deg:.2f}",
            f"{100 * clean.share:.4f}", f"{clean.max_change_deg:.1f}",
        )  # fmt: skip
    return table


@bench_app.command("twist")
def bench_twist(
    data: Annotated[
        Path | None, typer.Option(help="Folder of BVH takes (default: the corpus' bvh folder).")
    ] = None,
    seed: Annotated[int, typer.Option(help="Base seed of the injections.")] = 0,
    files: Annotated[int | None, typer.Option(help="Use the first N takes of each rig.")] = None,
    method: Annotated[
        list[str] | None, typer.Option(help="Methods to compare (repeatable; default both).")
    ] = None,
    repeats: Annotated[int, typer.Option(help="Injections per take.")] = 2,
    ablation: Annotated[
        bool, typer.Option(help="Also run the robust method with each idea switched off.")
    ] = False,
) -> None:
    """The paper's Tables 1 and 2, the clean-data figure and the speed, per rig and overall."""
    import numpy as np

    from mocapqa.bench.twist import find_bench_files, run_twist_bench, speed_frames_per_s
    from mocapqa.io.bvh import read_bvh

    methods_chosen = method or ["robust", "paper"]
    for m in methods_chosen:
        _check_method(m)
    data_dir = data if data is not None else _default_corpus()
    bench_files = find_bench_files(data_dir, files)
    methods: dict[str, tuple[str, Any]] = {m: (m, None) for m in methods_chosen}
    if ablation:
        methods.update(_ablations())
    console = Console(highlight=False, width=max(Console().width, 170))
    with Progress(console=console, transient=True) as progress:
        task = progress.add_task("twist bench", total=len(bench_files))
        result = run_twist_bench(
            bench_files,
            methods,
            seed=seed,
            repeats=repeats,
            on_file=lambda f: progress.update(task, advance=1, description=f.path.name),
        )
    console.print(
        f"{result.n_files} takes, {result.n_injections} injected takes per method, seed {seed}"
    )
    main_methods = {k: v for k, v in result.methods.items() if k in methods_chosen}
    console.print(_table1(main_methods))
    for label, res in main_methods.items():
        console.print(_table2(label, res))
    if ablation:
        console.print(_ablation_table(result.methods))
    cmu = [f for f in bench_files if f.rig == "cmu"]
    if cmu:
        motion = read_bvh(cmu[0].path)
        repeat = -(-100_000 // motion.n_frames)
        tiled = replace(
            motion,
            quats=np.tile(motion.quats, (repeat, 1, 1)),
            translations=np.tile(motion.translations, (repeat, 1, 1)),
            euler_hint_deg=None,
        )
        for m in methods_chosen:
            wall, cpu, full = speed_frames_per_s(tiled, m)
            console.print(
                f"speed ({m}), {motion.skeleton.n_joints}-joint take of {tiled.n_frames} frames: "
                f"detect + refine {wall:,.0f} frames/s wall-clock ({cpu:,.0f} per CPU second); "
                f"analyze_twist with Motion building {full:,.0f} frames/s"
            )
