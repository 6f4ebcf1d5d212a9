"""``mocapqa bench twist``: the paper's tables on injected errors, ablations, real-error,
clean-take, calibration and leave-one-rig-out figures, the speed, and (``--reviewers``) the
leave-one-take-out figures of learning from reviewers' decisions."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.progress import Progress

from mocapqa.cli.app import bench_app
from mocapqa_bench.cli.twist_real import print_real
from mocapqa_bench.cli.twist_tables import (
    ablation_table,
    calibration_table,
    disagreement_table,
    ends_table,
    loro_table,
    loro_variants,
    natural_levels_table,
    paper_table1,
    paper_table2,
    rates_table,
    rows_table,
    small_offsets_table,
    unpaired_table,
)

__all__ = ["bench_twist"]

ROBUST: dict[str, tuple[str, Any]] = {"robust": ("robust", None)}
"""The robust method with its defaults, as the runs beyond the paper's tables use it."""


def _check_method(method: str) -> None:
    from mocapqa.errors import InputError
    from mocapqa.twist.analysis import METHODS

    if method not in METHODS:
        raise InputError(f"Expected --method in {METHODS}, got {method!r}")


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


@dataclass(frozen=True, slots=True)
class _Bench:
    """The takes of one ``mocapqa bench twist`` run, its seed and injections per take, and the
    console its tables go to."""

    files: list[Any]
    seed: int
    repeats: int
    console: Console

    def run(
        self,
        methods: dict[str, tuple[str, Any]],
        apply: str = "confident",
        kind: str = "level",
        ends: str = "",
        files: list[Any] | None = None,
    ) -> Any:
        """:func:`mocapqa_bench.twist.run_twist_bench` over :attr:`files` (or ``files``), with a
        progress bar."""
        from mocapqa_bench.twist import run_twist_bench

        chosen = self.files if files is None else files
        with Progress(console=self.console, transient=True) as progress:
            task = progress.add_task("twist bench", total=len(chosen))
            return run_twist_bench(
                chosen,
                methods,
                seed=self.seed,
                repeats=self.repeats,
                on_file=lambda f: progress.update(task, advance=1, description=f.path.name),
                apply=apply,
                kind=kind,
                ends=ends,
            )  # fmt: skip

    def held_out_calibration(self, title: str, records: Sequence[Any], note: str = "") -> None:
        """Print the reliability of the held-out ``records``."""
        from mocapqa_bench.calibration import reliability

        held = [r for r in records if r.held_out]
        self.console.print(
            calibration_table(
                f"Calibration on the held-out takes, {title} ({len(held)} intervals{note})",
                reliability([r.confidence for r in held], [r.right for r in held]),
            )
        )


def _fit_natural_roll(bench: _Bench, output: Path) -> None:
    """Fit each rig's natural roll level on the clean fit takes and write it to ``output``."""
    from mocapqa.twist.natural_roll import fit_natural_roll
    from mocapqa_bench.twist_natural_roll import clean_event_jumps

    fit_files = [f for f in bench.files if not f.held_out]
    natural = fit_natural_roll(
        clean_event_jumps(fit_files),
        f"robust detector's event jumps (defaults) on {len(fit_files)} clean fit takes",
        output,
    )
    bench.console.print(f"natural roll levels written to {output}: {natural.fitted_on}")
    bench.console.print(natural_levels_table(clean_event_jumps(bench.files), natural))


def _fit_calibration(bench: _Bench, output: Path) -> None:
    """Fit the confidence calibration on the fit takes and write it to ``output``."""
    import numpy as np

    from mocapqa_bench.calibration import CALIBRATION_KINDS, fit_on_fit_takes, reliability
    from mocapqa_bench.unpaired import run_unpaired_bench

    fit_files = [f for f in bench.files if not f.held_out]
    records = [
        r
        for kind in CALIBRATION_KINDS
        for r in bench.run(ROBUST, "all", kind, files=fit_files).methods["robust"].records
    ]
    run_unpaired_bench(
        fit_files, seed=bench.seed, repeats=bench.repeats, apply="all", records=records
    )
    calibration = fit_on_fit_takes(records, output)
    bench.console.print(f"calibration written to {output}: {calibration.fitted_on}")
    probabilities = calibration.probability(np.array([r.features for r in records]))
    bins = reliability(probabilities.tolist(), [r.right for r in records])
    bench.console.print(calibration_table("Reliability on the fit takes (in-sample)", bins))


def _print_robust_kinds(bench: _Bench, levels: Any) -> list[Any]:
    """The robust method's natural roll levels, small offsets, bursts, clusters and ends, and
    its calibration on each kind; the interval records of the three kinds (``levels``: the
    robust result on level shifts)."""
    from mocapqa.twist.natural_roll import default_natural_roll
    from mocapqa_bench.calibration import disagreement_loro
    from mocapqa_bench.twist_natural_roll import clean_event_jumps, small_offset_rows

    console = bench.console
    natural = default_natural_roll()
    console.print(natural_levels_table(clean_event_jumps(bench.files), natural))
    held_out = [f for f in bench.files if f.held_out]
    console.print(
        small_offsets_table(small_offset_rows(held_out, natural, bench.seed, bench.repeats))
    )
    bursts = bench.run(ROBUST, kind="burst").methods
    console.print("Bursts of alternating flips (injected, kind=burst):")
    console.print(rates_table(bursts))
    clusters = bench.run(ROBUST, kind="cluster").methods
    console.print("Clusters of separate flips and holds (injected, kind=cluster):")
    console.print(rates_table(clusters))
    _print_ends(bench)
    kinds = (
        ("level shifts", levels.records),
        ("bursts", bursts["robust"].records),
        ("clusters", clusters["robust"].records),
    )
    for title, records in kinds:
        bench.held_out_calibration(title, records, ", injected and clean")
    disagreements = disagreement_loro([*levels.records, *bursts["robust"].records])
    console.print(disagreement_table(disagreements))
    return [r for _, records in kinds for r in records]


def _print_ends(bench: _Bench) -> None:
    """Only the table of errors at the take's ends (tail and head injections, ``apply``
    confident and all; per rig on the held-out takes, then all held-out and all fit takes)."""
    bench.console.print(
        ends_table([
            (where, apply_choice, bench.run(ROBUST, apply_choice, ends=where).methods["robust"])
            for where in ("tail", "head") for apply_choice in ("confident", "all")
        ])
    )  # fmt: skip


def _print_unpaired(bench: _Bench, injected: list[Any]) -> None:
    """Unpaired bursts and the calibration on them and on the bursts split off a group
    (``injected``: the interval records of the level shifts, bursts and clusters)."""
    from mocapqa.twist.intervals import FEATURES
    from mocapqa_bench.unpaired import run_unpaired_bench

    split = FEATURES.index("split")
    unpaired_records: list[Any] = []
    with Progress(console=bench.console, transient=True) as progress:
        task = progress.add_task("unpaired bursts", total=len(bench.files))
        unpaired = run_unpaired_bench(
            bench.files, seed=bench.seed, repeats=bench.repeats,
            on_file=lambda f: progress.update(task, advance=1, description=f.path.name),
            records=unpaired_records,
        )  # fmt: skip
    bench.console.print(unpaired_table(unpaired))
    bench.held_out_calibration("unpaired bursts", unpaired_records)
    split_off = [r for r in [*injected, *unpaired_records] if r.features and r.features[split] > 0]
    bench.held_out_calibration("bursts split off a group", split_off)


def _print_speed(bench: _Bench, methods_chosen: list[str]) -> None:
    """Frames per second of each method on the first CMU take tiled to 100,000 frames."""
    import numpy as np

    from mocapqa.io.bvh import read_bvh
    from mocapqa_bench.twist import speed_frames_per_s

    cmu = [f for f in bench.files if f.rig == "cmu"]
    if not cmu:
        return
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
        bench.console.print(
            f"speed ({m}), {motion.skeleton.n_joints}-joint take of {tiled.n_frames} frames: "
            f"detect + refine {wall:,.0f} frames/s wall-clock ({cpu:,.0f} per CPU second); "
            f"analyze_twist with Motion building {full:,.0f} frames/s"
        )


def _print_evidence(data_dir: Path, bench: _Bench) -> None:
    """What decided each interval (calibrated probability, anatomy, ends, natural roll) on the
    real errors, the clean takes and the held-out injected takes, with reliability."""
    from mocapqa_bench.twist_evidence import evidence_tables

    for title, rows in evidence_tables(data_dir, bench.seed, bench.repeats).items():
        bench.console.print(rows_table(f"Evidence: {title}", rows))


def _print_reviewers(data_dir: Path, bench: _Bench) -> None:
    """Leave-one-take-out removal and wrong-apply rates with and without the reviewer prior,
    per rig, and the same on the real-error take."""
    from mocapqa_bench.twist import REAL_ERROR_TAKES
    from mocapqa_bench.twist_reviewers import leave_one_take_out, real_take_rows, reviewed_takes

    for held_out, side in ((False, "fit (the rule was developed on these)"), (True, "held-out")):
        takes = reviewed_takes(bench.files, bench.seed, held_out)
        bench.console.print(
            rows_table(
                f"Learning from reviewers, leave one take out, {side}: {len(takes)} takes, one "
                f"injection each, seed {bench.seed}; 95 % bootstrap over takes",
                leave_one_take_out(takes),
            )
        )
    for path in sorted(p for p in data_dir.rglob("*.bvh") if p.name in REAL_ERROR_TAKES):
        bench.console.print(
            rows_table(
                f"Learning from reviewers on {path.name} (real errors; even intervals decided, "
                "odd ones by the default)",
                real_take_rows(path),
            )
        )


def _only(
    bench: _Bench,
    data_dir: Path,
    natural_roll: Path | None,
    calibration: Path | None,
    reviewers: bool,
    ends_only: bool = False,
) -> bool:
    """Run the one task a stopping option asks for (``--fit-natural-roll``,
    ``--fit-calibration``, ``--reviewers``, ``--ends-only``, in that order); whether one did."""
    if natural_roll is not None:
        _fit_natural_roll(bench, natural_roll)
    elif calibration is not None:
        _fit_calibration(bench, calibration)
    elif reviewers:
        _print_reviewers(data_dir, bench)
    elif ends_only:
        _print_ends(bench)
    return natural_roll is not None or calibration is not None or reviewers or ends_only


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
    reviewers: Annotated[
        bool,
        typer.Option(
            help="Only the leave-one-take-out figures of learning from reviewers' decisions."
        ),
    ] = False,
    ends_only: Annotated[
        bool, typer.Option(help="Only the table of errors at the take's ends (fit and held-out).")
    ] = False,
) -> None:
    """The paper's Tables 1 and 2 with bootstrap intervals, real-error, clean-take,
    calibration and (optionally) leave-one-rig-out figures, and the speed."""
    from mocapqa_bench.twist import find_bench_files

    methods_chosen = method or ["robust", "paper"]
    for m in methods_chosen:
        _check_method(m)
    data_dir = data if data is not None else _default_corpus()
    console = Console(highlight=False, width=max(Console().width, 170))
    bench = _Bench(find_bench_files(data_dir, files), seed, repeats, console)
    if _only(bench, data_dir, fit_natural_roll, fit_calibration, reviewers, ends_only):
        return
    methods: dict[str, tuple[str, Any]] = {m: (m, None) for m in methods_chosen}
    if ablation:
        methods.update(_ablations())
    result = bench.run(methods)
    console.print(
        f"{result.n_files} takes, {result.n_injections} injected takes per method, seed {seed}; "
        "the calibration was fitted on the fit set only; the robust defaults were chosen "
        "on the whole synthetic bench (see docs/twist.md)"
    )
    main_methods = {k: v for k, v in result.methods.items() if k in methods_chosen}
    console.print(paper_table1(main_methods))
    console.print(rates_table(main_methods))
    for label, res in main_methods.items():
        console.print(paper_table2(label, res))
    if "robust" in main_methods:
        _print_unpaired(bench, _print_robust_kinds(bench, main_methods["robust"]))
    if ablation:
        console.print(ablation_table(result.methods))
    if loro:
        grid = {
            label: bench.run({label: ("robust", params)}, "all").methods[label]
            for label, params in loro_variants().items()
        }
        console.print(loro_table(grid))
    if real:
        print_real(data_dir, console, methods_chosen)
    if real and "robust" in methods_chosen:
        _print_evidence(data_dir, bench)
    _print_speed(bench, methods_chosen)
