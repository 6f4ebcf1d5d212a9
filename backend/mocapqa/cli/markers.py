"""``mocapqa markers check``: gaps, swaps, spikes, segments, static markers and labels of a
marker take.

A C3D take is read with :func:`mocapqa.io.c3d.read_c3d`, any other keypoint take (TRC, CSV,
…) with :func:`mocapqa.io.formats.read_take`, both within the reading limits. ``--json``
prints the object of :meth:`mocapqa.markers.check.MarkerReport.to_json` (at least ``gaps``,
``swaps`` and ``spikes``; frames 0-based, ends inclusive; names the file's labels); without
it, Rich tables. The exit code is 0 whatever the take holds; errors exit as in every command
(3 for input errors).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from mocapqa.cli.app import app
from mocapqa.errors import InputError

if TYPE_CHECKING:
    from mocapqa.core.keypoints import KeypointSequence

__all__ = ["markers_app", "markers_check", "markers_fill", "read_marker_take"]

markers_app = typer.Typer(
    help="Optical marker takes: gaps, swaps, spikes, segments and labels.",
    no_args_is_help=True,
)
"""The ``mocapqa markers`` group."""
app.add_typer(markers_app, name="markers")

_ROWS = 20
"""Rows shown per table without ``--json`` (the JSON lists everything)."""


def read_marker_take(path: Path, fps: float | None = None) -> KeypointSequence:
    """The points of a C3D take, or a keypoint take of another format, within the settings'
    reading limits.

    Raises
    ------
    InputError
        When the file reads as a skeleton (BVH) rather than as points, or is not 3D.
    """
    from mocapqa.cli.reading import read_input
    from mocapqa.config import get_settings
    from mocapqa.core.keypoints import KeypointSequence
    from mocapqa.io.formats import detect_format

    if detect_format(path) == "c3d":
        from mocapqa.io.c3d import read_c3d

        return read_c3d(path, limits=get_settings().read_limits).points
    take = read_input(path, fps=fps)
    if not isinstance(take, KeypointSequence):
        raise InputError(f"Expected a marker or keypoint take, got a skeleton (BVH): {path}")
    if take.n_dims != 3:
        raise InputError(f"Expected 3D markers, got {take.n_dims}D keypoints: {path}")
    return take


def _print_report(path: Path, report: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console()
    unit = report["length_unit"]
    summary = Table(show_header=False, title=f"Markers: {path}", title_justify="left")
    summary.add_column("field", style="bold")
    summary.add_column("value", overflow="fold")
    missing = [s for s in report["gap_summary"] if s["count"]]
    rows = (
        ("frames", f"{report['frames']} at {report['fps']:.6g} fps"),
        ("markers", str(len(report["markers"]))),
        ("unit", unit),
        ("gaps", f"{len(report['gaps'])} in {len(missing)} markers"),
        ("swaps", str(len(report["swaps"]))),
        ("spikes", str(len(report["spikes"]))),
        ("segments", "; ".join(f"{s['name']} ({len(s['markers'])})" for s in report["segments"])
         or "none"),
        ("static / absent", ", ".join(f"{s['marker']} ({s['kind']})" for s in report["static"])
         or "none"),
        ("labels", ", ".join(f"{f['kind']} {'/'.join(f['markers'])}" for f in report["labels"])
         or "ok"),
    )  # fmt: skip
    for key, value in rows:
        summary.add_row(key, value)
    console.print(summary)
    gaps = Table(title="Gaps by marker", title_justify="left")
    for column in ("marker", "gaps", "longest (frames)", "longest (s)", "missing"):
        gaps.add_column(column, justify="left" if column == "marker" else "right")
    worst = sorted(missing, key=lambda s: -s["missing"])
    for s in worst[:_ROWS]:
        gaps.add_row(s["marker"], str(s["count"]), str(s["longest"]), f"{s['longest_s']:.2f}",
                     f"{100 * s['missing']:.1f} %")  # fmt: skip
    gaps.caption = "none" if not worst else (
        f"{len(worst) - _ROWS} more in --json" if len(worst) > _ROWS else None
    )  # fmt: skip
    console.print(gaps)
    swaps = Table(title="Swaps", title_justify="left")
    for column in ("markers", "frames", "confidence"):
        swaps.add_column(column, justify="left" if column == "markers" else "right")
    for w in report["swaps"][:_ROWS]:
        swaps.add_row(" ↔ ".join(w["markers"]), f"{w['start']}–{w['end']}",
                      f"{w['confidence']:.2f}")  # fmt: skip
    swaps.caption = "none" if not report["swaps"] else None
    console.print(swaps)
    spikes = Table(title="Spikes", title_justify="left")
    for column in ("marker", "frames", "peak", "off path"):
        spikes.add_column(column, justify="left" if column == "marker" else "right")
    for s in report["spikes"][:_ROWS]:
        spikes.add_row(s["marker"], f"{s['start']}–{s['end']}", str(s["peak"]),
                       f"{s['offset']:.4g} {unit}")  # fmt: skip
    spikes.caption = "none" if not report["spikes"] else (
        f"{len(report['spikes']) - _ROWS} more in --json" if len(report["spikes"]) > _ROWS
        else None
    )  # fmt: skip
    console.print(spikes)


@markers_app.command("check")
def markers_check(
    take: Annotated[Path, typer.Argument(help="A C3D take, or a TRC or other keypoint take.")],
    json_output: Annotated[bool, typer.Option("--json", help="Print JSON instead.")] = False,
    fps: Annotated[
        float | None,
        typer.Option("--fps", help="Frames per second, for keypoint formats that store none."),
    ] = None,
) -> None:
    """Find gaps, swaps, spikes, segments, static markers and label problems."""
    from mocapqa.io.formats import check_fps
    from mocapqa.markers.check import check_markers

    if fps is not None:
        check_fps(fps, "--fps")
    points = read_marker_take(take, fps)
    report = check_markers(points.positions, points.names, points.fps, points.length_unit)
    result = {"path": str(take), **report.to_json()}
    if json_output:
        typer.echo(json.dumps(result, indent=2))
    else:
        _print_report(take, result)


@markers_app.command("fill")
def markers_fill(
    take: Annotated[Path, typer.Argument(help="A C3D take (or a TRC or other marker take).")],
    output: Annotated[
        Path, typer.Option("-o", "--output", help="The repaired take (.c3d, .trc, ...).")
    ],
    apply: Annotated[
        str, typer.Option(help="Which swaps and fills change the take: confident, all or none.")
    ] = "confident",
    report: Annotated[
        Path | None, typer.Option("--report", help="Write what was found and done as JSON.")
    ] = None,
    fps: Annotated[
        float | None,
        typer.Option("--fps", help="Frames per second, for keypoint formats that store none."),
    ] = None,
) -> None:
    """Repair swaps, then fill gaps (each by its best cross-validated method), and write the
    take: every filled sample is marked (residual 0 in a C3D), every other sample unchanged."""
    import dataclasses

    import numpy as np

    from mocapqa.cli.outputs import check_outputs
    from mocapqa.io.atomic import write_text
    from mocapqa.io.formats import check_fps, detect_format, write_keypoints
    from mocapqa.markers.repair import repair_markers
    from mocapqa.markers.swap_repair import APPLY_RULES

    if fps is not None:
        check_fps(fps, "--fps")
    if apply not in APPLY_RULES:
        raise InputError(f"Expected --apply among {', '.join(APPLY_RULES)}, got {apply!r}")
    check_outputs({"-o": output, "--report": report}, [take])
    is_c3d = detect_format(take) == "c3d"
    if output.suffix.lower() == ".c3d" and not is_c3d:
        raise InputError(f"Expected a C3D input for a .c3d output, got {take.name!r}")
    marker_take = None
    if is_c3d:
        from mocapqa.config import get_settings
        from mocapqa.io.c3d import read_c3d

        marker_take = read_c3d(take, limits=get_settings().read_limits)
        points, residuals = marker_take.points, marker_take.residuals
    else:
        points = read_marker_take(take, fps)
        residuals = np.where(points.missing, -1.0, 0.0)
    repaired = repair_markers(
        points.positions,
        residuals,
        points.names,
        points.fps,
        points.length_unit,
        apply,  # type: ignore[arg-type]
    )
    new_points = dataclasses.replace(points, positions=repaired.positions)
    if output.suffix.lower() == ".c3d" and marker_take is not None:
        from mocapqa.io.c3d import write_c3d

        fixed = dataclasses.replace(marker_take, points=new_points, residuals=repaired.residuals)
        write_c3d(output, fixed, source=take)
    else:
        write_keypoints(output, new_points)
    account = {"path": str(take), "output": str(output), "apply": apply,
               **repaired.to_json(points.names, points.length_unit)}  # fmt: skip
    if report is not None:
        write_text(report, json.dumps(account, indent=2) + "\n")
    gaps = account["gaps"]
    typer.echo(
        f"wrote {output}: {sum(s['applied'] for s in account['swaps'])} of "
        f"{len(account['swaps'])} swaps repaired, {sum(g['applied'] for g in gaps)} of "
        f"{len(gaps)} gaps filled ({account['filled_samples']} samples marked filled)"
    )
