"""``mocapqa refine`` and ``mocapqa detect``: axial twist errors (the benchmark:
:mod:`mocapqa_bench.cli.bench_twist`)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from mocapqa.cli.app import app
from mocapqa.cli.outputs import check_outputs, require_suffix
from mocapqa.cli.reading import read_input_bvh
from mocapqa.cli.roles import MappingOption, load_mapping, missing_roles
from mocapqa.pipeline.options import DEFAULT_OPTIONS

if TYPE_CHECKING:
    from mocapqa.twist.analysis import TwistAnalysis
    from mocapqa.twist.spin import LimbSpin

__all__ = ["detect", "refine"]

_METHOD_HELP = "Detector: robust or paper (the published rule as written)."
_APPLY_HELP = (
    "Intervals to remove: confident (calibrated probability ≥ 0.5 and a level of at least "
    "5°), all, none, or interval ids from the report such as 0,3."
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


def _analysed(
    input_path: Path, mapping: Path | None, method: str, apply: str
) -> tuple[TwistAnalysis, list[str], list[LimbSpin]]:
    """Read the take and analyse its twist: the analysis, the roles neither found by name nor
    in the mapping, and the limb spins."""
    from mocapqa.io.formats import require_frames
    from mocapqa.twist.analysis import analyze_twist
    from mocapqa.twist.spin import find_limb_spins

    roles = load_mapping(mapping)
    motion = read_input_bvh(input_path)
    require_frames(motion, input_path)
    missing = missing_roles(motion.skeleton, roles)
    analysis = analyze_twist(motion, method, roles, apply=apply)
    return analysis, missing, find_limb_spins(motion, mapping=roles)


@app.command()
def refine(
    input_path: Annotated[Path, typer.Argument(metavar="IN.bvh", help="Take to refine.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Refined BVH to write.")],
    method: Annotated[str, typer.Option(help=_METHOD_HELP)] = DEFAULT_OPTIONS.twist_method,
    apply: Annotated[str, typer.Option(help=_APPLY_HELP)] = DEFAULT_OPTIONS.twist_apply,
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

    _check_method(method)
    require_suffix("-o", output, (".bvh",), "a BVH take")
    check_outputs({"-o": output, "--report": report}, [input_path, mapping])
    analysis, missing, spins = _analysed(input_path, mapping, method, apply)
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
    method: Annotated[str, typer.Option(help=_METHOD_HELP)] = DEFAULT_OPTIONS.twist_method,
    apply: Annotated[str, typer.Option(help=_APPLY_HELP)] = DEFAULT_OPTIONS.twist_apply,
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
    mapping: MappingOption = None,
) -> None:
    """Report axial twist error intervals (and which refine would apply) without writing."""
    _check_method(method)
    analysis, missing, spins = _analysed(input_path, mapping, method, apply)
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
