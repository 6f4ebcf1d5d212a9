"""``mocapqa feet check``: up axis, floor, foot contacts and foot findings of a take.

The take is read through :func:`mocapqa.cli.reading.read_input` (the reading limits apply);
BVH, keypoint and C3D marker takes work (:mod:`mocapqa.pipeline.feet`; a C3D take's heel and
toe markers are found by name, :mod:`mocapqa.feet.markers`). ``--json`` prints the report
object of :func:`mocapqa.pipeline.feet.feet_report_json`; without it, Rich tables. The exit
code is 0 whatever the take holds; errors exit as in every command (3 for input errors).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer

from mocapqa.cli.app import app
from mocapqa.cli.reading import read_input
from mocapqa.cli.roles import FpsOption, MappingOption, RootTranslationOption, load_mapping
from mocapqa.errors import InputError

__all__ = ["feet_app", "feet_check"]

feet_app = typer.Typer(
    help="Feet and ground: up axis, floor, contacts, skate and penetration.",
    no_args_is_help=True,
)
"""The ``mocapqa feet`` group."""
app.add_typer(feet_app, name="feet")


def _size(item: dict[str, Any]) -> str:
    if item["size_cm"] is not None:
        return f"{item['size_cm']:.1f} cm"
    return f"{100 * item['size_rel_height']:.2f} % of height"


def _print_report(path: Path, report: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console()
    check = report["floor_check"]
    unit = report["length_unit"]
    summary = Table(show_header=False, title=f"Feet: {path}", title_justify="left")
    summary.add_column("field", style="bold")
    summary.add_column("value", overflow="fold")
    tilt = "not measured (too small an area)" if check["tilt_deg"] is None else (
        f"{check['tilt_deg']:.2f}°" + (" [yellow]tilted[/]" if check["tilted"] else "")
    )  # fmt: skip
    drift = f"{check['drift']:.4g} {unit}" + (
        f" ({check['drift_cm']:.1f} cm)" if check["drift_cm"] is not None else ""
    )
    rows = (
        ("frames", f"{report['frames']} at {report['fps']:.6g} fps"
         + (" (frame 0 is a bind pose, not checked)" if report["bind_pose_frames"] else "")),
        ("up axis", f"{report['up_axis']} ({report['up_axis_detail']['method']})"),
        ("floor", f"{report['up_axis'].lstrip('-')} = {report['floor']:.5g} {unit}"),
        ("floor tilt", tilt),
        ("floor drift", drift + (" [yellow]moving[/]" if check["moving"] else "")),
        ("leg length", f"{report['leg_length']:.4g} {unit}"),
        ("sizes", report["sizes"]),
        ("contacts", ", ".join(f"{foot} {n}" for foot, n in report["summary"]["contacts"].items())),
    )  # fmt: skip
    for key, value in rows:
        summary.add_row(key, value)
    console.print(summary)
    fps = report["fps"]
    contacts = Table(title="Contacts", title_justify="left")
    for column in ("foot", "frames", "seconds", "confidence"):
        contacts.add_column(column, justify="left" if column == "foot" else "right")
    for c in report["contacts"]:
        seconds = (c["end"] - c["start"] + 1) / fps
        contacts.add_row(
            c["foot"], f"{c['start']}–{c['end']}", f"{seconds:.2f}", f"{c['confidence']:.2f}"
        )
    console.print(contacts)
    findings = Table(title="Findings", title_justify="left")
    for column in ("kind", "foot", "frames", "size", "speed"):
        findings.add_column(column, justify="left" if column in ("kind", "foot") else "right")
    for f in report["findings"]:
        speed = f.get("speed_cm_s")
        findings.add_row(
            f["kind"], f["foot"], f"{f['start']}–{f['end']}", _size(f),
            "" if "speed_rel_height_s" not in f else (
                f"{speed:.1f} cm/s" if speed is not None
                else f"{100 * f['speed_rel_height_s']:.2f} % of height/s"
            ),
        )  # fmt: skip
    if not report["findings"]:
        findings.caption = "none"
    console.print(findings)


@feet_app.command("check")
def feet_check(
    take: Annotated[Path, typer.Argument(help="A BVH, keypoint or C3D take (or OpenPose folder).")],
    json_output: Annotated[bool, typer.Option("--json", help="Print JSON instead.")] = False,
    fps: FpsOption = None,
    length_unit: Annotated[
        str | None,
        typer.Option(
            "--length-unit",
            help="The take's length unit (m, cm, mm, in), for files that do not store it "
            "(BVH): sizes are then given in cm.",
        ),
    ] = None,
    mapping: MappingOption = None,
    root_translation: RootTranslationOption = "auto",
) -> None:
    """Find the up axis, the floor, foot contacts, skate, penetration, floating and jitter."""
    from mocapqa.core.keypoints import LENGTH_UNITS
    from mocapqa.io.formats import check_fps
    from mocapqa.pipeline.feet import check_take_feet, feet_report_json

    if fps is not None:
        check_fps(fps, "--fps")
    if length_unit is not None and length_unit not in LENGTH_UNITS:
        raise InputError(
            f"Expected --length-unit among {', '.join(LENGTH_UNITS)}, got {length_unit!r}"
        )
    roles = load_mapping(mapping)
    read = read_input(
        take, fps=fps, length_unit=length_unit, number_reader="auto",
        root_translation=root_translation,
    )  # fmt: skip
    points, report, skipped = check_take_feet(read, roles)
    result = {"path": str(take), **feet_report_json(points, report, skipped)}
    if json_output:
        typer.echo(json.dumps(result, indent=2))
    else:
        _print_report(take, result)
