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
from mocapqa.cli.outputs import check_outputs, require_suffix
from mocapqa.cli.reading import read_input_bvh
from mocapqa.cli.roles import MappingOption, load_mapping, missing_roles

if TYPE_CHECKING:
    from mocapqa.twist.analysis import TwistAnalysis
    from mocapqa.twist.spin import LimbSpin

__all__ = ["bench_twist", "detect", "refine"]

_METHOD_HELP = "Detector: robust (default) or paper (the published rule as written)."
_APPLY_HELP = (
    "Intervals to remove: confident (calibrated probability ≥ 0.5 and a level of at least 5°, "
    "the default), all, none, or interval ids from the report such as 0,3."
)


def _report(
    analysis: TwistAnalysis, path: Path, missing: list[str], spins: list[LimbSpin]
) -> dict[str, Any]:
    return {
        "input": str(path),
        "method": analysis.method,
        "missing_roles": missing,
        "apply": analysis.apply,
        "n_frames": analysis.refined.n_frames,
        "fps": analysis.fps,
        "intervals": [i.to_json() for i in analysis.intervals],
        "joints": analysis.summaries(),
        "spins": [spin.to_json() for spin in spins],
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
    apply: Annotated[str, typer.Option(help=_APPLY_HELP)] = "confident",
    report: Annotated[
        Path | None, typer.Option(help="Write the intervals and per-joint summaries as JSON.")
    ] = None,
    mapping: MappingOption = None,
) -> None:
    """Remove axial twist errors; writes the take with the input's layout and frame time.

    Every interval found is listed in the report with its confidence and whether it was
    applied; the written take is the input with exactly the applied intervals' levels removed.
    """
    from mocapqa.io.atomic import write_text
    from mocapqa.io.bvh_write import write_bvh
    from mocapqa.io.formats import require_frames
    from mocapqa.twist.analysis import analyze_twist
    from mocapqa.twist.spin import find_limb_spins

    _check_method(method)
    require_suffix("-o", output, (".bvh",), "a BVH take")
    check_outputs({"-o": output, "--report": report}, [input_path, mapping])
    roles = load_mapping(mapping)
    motion = read_input_bvh(input_path)
    require_frames(motion, input_path)
    missing = missing_roles(motion.skeleton, roles)
    analysis = analyze_twist(motion, method, roles, apply=apply)
    spins = find_limb_spins(motion, mapping=roles)
    write_bvh(output, analysis.refined)
    if report is not None:
        write_text(report, json.dumps(_report(analysis, input_path, missing, spins), indent=2))
    console = Console(highlight=False)
    applied = [i for i in analysis.intervals if i.applied]
    frames = sum(i.end_frame - i.start_frame + 1 for i in applied)
    console.print(
        f"{len(applied)} of {len(analysis.intervals)} intervals applied ({frames} joint frames) "
        f"→ {output}"
    )
    for spin in spins:
        console.print(f"frames {spin.start_frame}–{spin.end_frame}: {spin.readout()}")


@app.command()
def detect(
    input_path: Annotated[Path, typer.Argument(metavar="IN.bvh", help="Take to check.")],
    method: Annotated[str, typer.Option(help=_METHOD_HELP)] = "robust",
    apply: Annotated[str, typer.Option(help=_APPLY_HELP)] = "confident",
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
    mapping: MappingOption = None,
) -> None:
    """Report axial twist error intervals (and which refine would apply) without writing."""
    from mocapqa.io.formats import require_frames
    from mocapqa.twist.analysis import analyze_twist
    from mocapqa.twist.spin import find_limb_spins

    _check_method(method)
    roles = load_mapping(mapping)
    motion = read_input_bvh(input_path)
    require_frames(motion, input_path)
    missing = missing_roles(motion.skeleton, roles)
    analysis = analyze_twist(motion, method, roles, apply=apply)
    spins = find_limb_spins(motion, mapping=roles)
    if as_json:
        typer.echo(json.dumps(_report(analysis, input_path, missing, spins), indent=2))
        return
    table = Table(title=f"Twist intervals ({method}) in {input_path.name}")
    for column in ("id", "joint", "start", "end", "offset °", "confidence", "applied"):
        table.add_column(column, justify="left" if column == "joint" else "right")
    for i in analysis.intervals:
        table.add_row(
            str(i.id),
            i.joint,
            str(i.start_frame),
            str(i.end_frame),
            f"{i.offset_deg:.1f}",
            f"{i.confidence:.2f}",
            "yes" if i.applied else "no",
        )
    console = Console(highlight=False)
    console.print(table)
    if spins:
        spun = Table(title=f"Limb spins and flips in {input_path.name} (reported, not corrected)")
        for column in ("limb", "shape", "start", "end", "roll °", "hand/foot °", "peak °/s"):
            spun.add_column(column, justify="left" if column in ("limb", "shape") else "right")
        for spin in spins:
            spun.add_row(
                f"{spin.side} {spin.limb} ({spin.joint})", spin.shape, str(spin.start_frame),
                str(spin.end_frame), f"{spin.value_deg:.1f}", f"{spin.end_roll_deg:.1f}",
                f"{spin.peak_rate_deg_s:,.0f}",
            )  # fmt: skip
        console.print(spun)


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
        "no local-speed rule": ("robust", replace(base, speed_factor=0.0)),
        "jump weighted by parent/child noise": ("robust", replace(base, weighted_jumps=True)),
        "mismatch allowance + 1 noise scale": ("robust", replace(base, mismatch_noise=1.0)),
        "no closure allowance (closure_noise 0)": ("robust", replace(base, closure_noise=0.0)),
        "outside level overrules within its scatter": ("robust", replace(base, precision=0.0)),
        "no mirror check (mirror 0)": ("robust", replace(base, mirror=0.0)),
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


def _run(
    bench_files: list[Any],
    methods: dict[str, Any],
    seed: int,
    repeats: int,
    console: Console,
    apply: str = "confident",
    kind: str = "level",
    ends: str = "",
) -> Any:
    from mocapqa.bench.twist import run_twist_bench

    with Progress(console=console, transient=True) as progress:
        task = progress.add_task("twist bench", total=len(bench_files))
        return run_twist_bench(
            bench_files,
            methods,
            seed=seed,
            repeats=repeats,
            on_file=lambda f: progress.update(task, advance=1, description=f.path.name),
            apply=apply,
            kind=kind,
            ends=ends,
        )  # fmt: skip


def _real_takes(data_dir: Path) -> list[Path]:
    return sorted(p for p in data_dir.rglob("*.bvh") if p.is_file())


def _print_real(data_dir: Path, console: Console, methods_chosen: list[str]) -> None:
    """Natural-error figures on the real-error takes and the default refinement of every take."""
    from mocapqa.bench.calibration import real_interval_records, reliability
    from mocapqa.bench.natural import (
        CLEAN_RATES,
        clean_figures_at_rates,
        clean_take_figure,
        natural_error_figures,
    )
    from mocapqa.bench.twist import REAL_ERROR_TAKES
    from mocapqa.cli.twist_tables import calibration_table, clean_takes_table, natural_table
    from mocapqa.io.bvh import read_bvh
    from mocapqa.twist.analysis import analyze_twist

    takes = _real_takes(data_dir)
    for path in (p for p in takes if p.name in REAL_ERROR_TAKES):
        motion = read_bvh(path)
        rows = [
            (f"{m} (apply {a})", natural_error_figures(motion, analyze_twist(motion, m, apply=a)))
            for m in methods_chosen
            for a in (("confident", "all") if m == "robust" else ("all",))
        ]
        console.print(f"{path.parent.name}/{path.name}: {motion.n_frames} frames, {motion.fps} fps")
        console.print(natural_table(rows))
        if "robust" in methods_chosen:
            records = real_interval_records(motion, path.name, "iclone")
            console.print(
                calibration_table(
                    f"Calibration on the real intervals of {path.name} "
                    f"({sum(r.right for r in records)} of {len(records)} right)",
                    reliability([r.confidence for r in records], [r.right for r in records]),
                )
            )
    rows_clean = []
    for path in takes:
        motion = read_bvh(path)
        rows_clean.append((path, (motion, clean_take_figure(motion, analyze_twist(motion)))))
    console.print(clean_takes_table(rows_clean))
    clean_rows = [r for p, r in rows_clean if p.name not in REAL_ERROR_TAKES]
    console.print(
        f"takes without real errors: {len(clean_rows)}, with an interval applied by default: "
        f"{sum(f.n_applied > 0 for _, f in clean_rows)}, intervals applied: "
        f"{sum(f.n_applied for _, f in clean_rows)}, largest change "
        f"{max((f.max_change_deg for _, f in clean_rows), default=0.0):.1f}°"
    )
    spun = [p.name for p, (_, f) in rows_clean if f.n_spins + f.n_flips]
    console.print(
        f"real takes with a limb spin or flip reported (never applied): {len(spun)} of "
        f"{len(rows_clean)}: {', '.join(spun) or 'none'}"
    )
    # The same clean takes at other common frame rates: the decisions should not change.
    resampled = [
        (path.name, fps, figure)
        for path, (motion, _) in rows_clean
        if path.name not in REAL_ERROR_TAKES
        for fps, figure in clean_figures_at_rates(motion)
    ]
    applied = [(name, fps, f) for name, fps, f in resampled if f.n_applied]
    spinning = sorted({name for name, _, f in resampled if f.n_spins + f.n_flips})
    console.print(
        f"takes without real errors resampled to {', '.join(f'{r:g}' for r in CLEAN_RATES)} "
        f"fps: {len(resampled)} take-rates, with an interval applied by default: {len(applied)}; "
        f"with a limb spin or flip: "
        f"{sum(1 for _, _, f in resampled if f.n_spins + f.n_flips)} "
        f"(takes: {', '.join(spinning) or 'none'})"
        + "".join(
            f"\n  {name} at {fps:g} fps: {f.n_applied} applied, largest change "
            f"{f.max_change_deg:.1f}°"
            for name, fps, f in applied
        )
    )


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
    loro: Annotated[
        bool, typer.Option(help="Also choose parameters on two rigs and report the third.")
    ] = False,
    real: Annotated[
        bool, typer.Option(help="Real-error figures (005_05) and the default on every take.")
    ] = True,
    fit_calibration: Annotated[
        Path | None,
        typer.Option(help="Fit the confidence calibration on the fit takes, write it here, stop."),
    ] = None,
    fit_natural_roll: Annotated[
        Path | None,
        typer.Option(
            help="Read each rig's natural roll level from its clean fit takes, write it here, stop."
        ),
    ] = None,
) -> None:
    """The paper's Tables 1 and 2 with bootstrap intervals, real-error, clean-take,
    calibration and (optionally) leave-one-rig-out figures, and the speed."""
    import numpy as np

    from mocapqa.bench.calibration import (
        CALIBRATION_KINDS,
        disagreement_loro,
        fit_on_fit_takes,
        reliability,
    )
    from mocapqa.bench.twist import (
        clean_event_jumps,
        find_bench_files,
        small_offset_rows,
        speed_frames_per_s,
    )
    from mocapqa.bench.unpaired import run_unpaired_bench
    from mocapqa.cli.twist_tables import (
        calibration_table,
        disagreement_table,
        ends_table,
        loro_table,
        loro_variants,
        natural_levels_table,
        rates_table,
        rows_table,
        small_offsets_table,
        unpaired_table,
    )
    from mocapqa.io.bvh import read_bvh
    from mocapqa.twist.intervals import FEATURES
    from mocapqa.twist.natural_roll import default_natural_roll
    from mocapqa.twist.natural_roll import fit_natural_roll as fit_levels

    split = FEATURES.index("split")
    methods_chosen = method or ["robust", "paper"]
    for m in methods_chosen:
        _check_method(m)
    data_dir = data if data is not None else _default_corpus()
    bench_files = find_bench_files(data_dir, files)
    console = Console(highlight=False, width=max(Console().width, 170))
    if fit_natural_roll is not None:
        fit_files = [f for f in bench_files if not f.held_out]
        natural = fit_levels(
            clean_event_jumps(fit_files),
            f"robust detector's event jumps (defaults) on {len(fit_files)} clean fit takes",
            fit_natural_roll,
        )
        console.print(f"natural roll levels written to {fit_natural_roll}: {natural.fitted_on}")
        console.print(natural_levels_table(clean_event_jumps(bench_files), natural))
        return
    if fit_calibration is not None:
        fit_files = [f for f in bench_files if not f.held_out]
        records = [
            r
            for kind in CALIBRATION_KINDS
            for r in _run(fit_files, {"robust": ("robust", None)}, seed, repeats, console, "all",
                          kind).methods["robust"].records
        ]  # fmt: skip
        run_unpaired_bench(fit_files, seed=seed, repeats=repeats, apply="all", records=records)
        calibration = fit_on_fit_takes(records, fit_calibration)
        console.print(f"calibration written to {fit_calibration}: {calibration.fitted_on}")
        probabilities = calibration.probability(np.array([r.features for r in records]))
        bins = reliability(probabilities.tolist(), [r.right for r in records])
        console.print(calibration_table("Reliability on the fit takes (in-sample)", bins))
        return
    methods: dict[str, tuple[str, Any]] = {m: (m, None) for m in methods_chosen}
    if ablation:
        methods.update(_ablations())
    result = _run(bench_files, methods, seed, repeats, console)
    console.print(
        f"{result.n_files} takes, {result.n_injections} injected takes per method, seed {seed}; "
        "the calibration was fitted on the fit set only; the robust defaults were chosen "
        "on the whole synthetic bench (see docs/twist.md)"
    )
    main_methods = {k: v for k, v in result.methods.items() if k in methods_chosen}
    console.print(_table1(main_methods))
    console.print(rates_table(main_methods))
    for label, res in main_methods.items():
        console.print(_table2(label, res))
    if "robust" in main_methods:
        natural = default_natural_roll()
        console.print(natural_levels_table(clean_event_jumps(bench_files), natural))
        held_out = [f for f in bench_files if f.held_out]
        console.print(small_offsets_table(small_offset_rows(held_out, natural, seed, repeats)))
        bursts = _run(bench_files, {"robust": ("robust", None)}, seed, repeats, console,
                      kind="burst").methods  # fmt: skip
        console.print("Bursts of alternating flips (injected, kind=burst):")
        console.print(rates_table(bursts))
        clusters = _run(bench_files, {"robust": ("robust", None)}, seed, repeats, console,
                        kind="cluster").methods  # fmt: skip
        console.print("Clusters of separate flips and holds (injected, kind=cluster):")
        console.print(rates_table(clusters))
        console.print(
            ends_table([
                (where, apply_choice,
                 _run(bench_files, {"robust": ("robust", None)}, seed, repeats, console,
                      apply_choice, ends=where).methods["robust"])
                for where in ("tail", "head") for apply_choice in ("confident", "all")
            ])
        )  # fmt: skip
        for title, records in (
            ("level shifts", main_methods["robust"].records),
            ("bursts", bursts["robust"].records),
            ("clusters", clusters["robust"].records),
        ):
            held = [r for r in records if r.held_out]
            console.print(
                calibration_table(
                    f"Calibration on the held-out takes, {title} ({len(held)} intervals, "
                    "injected and clean)",
                    reliability([r.confidence for r in held], [r.right for r in held]),
                )
            )
        console.print(
            disagreement_table(
                disagreement_loro([*main_methods["robust"].records, *bursts["robust"].records])
            )
        )
        unpaired_records: list[Any] = []
        with Progress(console=console, transient=True) as progress:
            task = progress.add_task("unpaired bursts", total=len(bench_files))
            unpaired = run_unpaired_bench(
                bench_files, seed=seed, repeats=repeats,
                on_file=lambda f: progress.update(task, advance=1, description=f.path.name),
                records=unpaired_records,
            )  # fmt: skip
        console.print(unpaired_table(unpaired))
        for title, records in (
            ("unpaired bursts", unpaired_records),
            ("bursts split off a group", [
                r for r in [*main_methods["robust"].records, *bursts["robust"].records,
                            *clusters["robust"].records, *unpaired_records]
                if r.features and r.features[split] > 0
            ]),
        ):  # fmt: skip
            held = [r for r in records if r.held_out]
            console.print(
                calibration_table(
                    f"Calibration on the held-out takes, {title} ({len(held)} intervals)",
                    reliability([r.confidence for r in held], [r.right for r in held]),
                )
            )
    if ablation:
        console.print(_ablation_table(result.methods))
    if loro:
        grid = {
            label: _run(bench_files, {label: ("robust", params)}, seed, repeats, console,
                        "all").methods[label]
            for label, params in loro_variants().items()
        }  # fmt: skip
        console.print(loro_table(grid))
    if real:
        _print_real(data_dir, console, methods_chosen)
    if real and "robust" in methods_chosen:
        # What decided each interval (calibrated probability, anatomy, ends, natural roll) on
        # the real errors, the clean takes and the held-out injected takes, with reliability.
        from mocapqa.bench.twist_evidence import evidence_tables

        for title, rows in evidence_tables(data_dir, seed, repeats).items():
            console.print(rows_table(f"Evidence: {title}", rows))
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
