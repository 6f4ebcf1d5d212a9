"""``mocapqa feet check``: up axis, floor, foot contacts and foot findings of a take;
``mocapqa feet fix``: the same take with chosen contacts locked (BVH, keypoint and C3D takes).

The take is read through :func:`mocapqa.cli.reading.read_input` (the reading limits apply);
BVH, keypoint and C3D marker takes work (:mod:`mocapqa.pipeline.feet`; a C3D take's heel and
toe markers are found by name, :mod:`mocapqa.feet.markers`). ``--json`` prints the report
object of :func:`mocapqa.pipeline.feet.feet_report_json`; without it, Rich tables. The exit
code is 0 whatever the take holds; errors exit as in every command (3 for input errors).

``feet fix`` checks the take, locks the contacts ``--apply`` names
(:func:`mocapqa.feet.fix.fix_feet`, what the reviewed download does too; BVH:
:func:`mocapqa.feet.fix.lock_feet`, keypoints and C3D markers: :func:`mocapqa.feet.pin.pin_feet`),
writes the take (a C3D with its analogs and force plates) and
reports every finding and contact with applied or not and its slide before and after
(:func:`mocapqa.feet.fix_report.fix_report_json`), printed with ``--json`` and written with
``--report``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import typer

from mocapqa.cli.app import app
from mocapqa.cli.reading import read_input
from mocapqa.cli.roles import FpsOption, MappingOption, RootTranslationOption, load_mapping
from mocapqa.errors import InputError

if TYPE_CHECKING:
    from mocapqa.core.keypoints import KeypointSequence
    from mocapqa.core.motion import Motion

__all__ = ["feet_app", "feet_check", "feet_fix"]

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


LengthUnitOption = Annotated[
    str | None,
    typer.Option(
        "--length-unit",
        help="The take's length unit (m, cm, mm, in), for files that do not store it "
        "(BVH): sizes are then given in cm.",
    ),
]
"""The ``--length-unit`` option of the feet commands."""


def _read_take(
    take: Path,
    fps: float | None,
    length_unit: str | None,
    mapping: Path | None,
    root_translation: Literal["auto", "add", "replace"],
) -> tuple[Any, Any]:
    """The take and its hand-named roles, the options checked first (``--fps``,
    ``--length-unit``, ``--mapping``)."""
    from mocapqa.core.keypoints import LENGTH_UNITS
    from mocapqa.io.formats import check_fps

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
    return read, roles


@feet_app.command("check")
def feet_check(
    take: Annotated[Path, typer.Argument(help="A BVH, keypoint or C3D take (or OpenPose folder).")],
    json_output: Annotated[bool, typer.Option("--json", help="Print JSON instead.")] = False,
    fps: FpsOption = None,
    length_unit: LengthUnitOption = None,
    mapping: MappingOption = None,
    root_translation: RootTranslationOption = "auto",
) -> None:
    """Find the up axis, the floor, foot contacts, skate, penetration, floating and jitter."""
    from mocapqa.feet.fix_choice import add_ids
    from mocapqa.pipeline.feet import check_take_feet, feet_report_json

    read, roles = _read_take(take, fps, length_unit, mapping, root_translation)
    points, report, skipped = check_take_feet(read, roles)
    result = {"path": str(take), **feet_report_json(points, report, skipped)}
    add_ids(result, report.contacts, report.findings, skipped)
    if json_output:
        typer.echo(json.dumps(result, indent=2))
    else:
        _print_report(take, result)


def _print_fix(path: Path, out: Path, result: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    def slide(item: dict[str, Any], key: str) -> str:
        if item.get(key) is None:
            return ""
        cm = item[f"{key}_cm"]
        return f"{cm:.2f} cm" if cm is not None else f"{100 * item[f'{key}_rel_height']:.2f} %"

    table = Table(title=f"Feet fix: {path} → {out}", title_justify="left")
    for column in ("id", "frames", "confidence", "applied", "slide before", "after", "clamped"):
        table.add_column(
            column, justify="left" if column == "id" else "right", no_wrap=column == "id"
        )
    for item in result["findings"]:
        confidence = item["confidence"]
        table.add_row(
            item["id"], f"{item['start']}–{item['end']}",
            "" if confidence is None else f"{confidence:.2f}",
            "yes" if item["applied"] else "no", slide(item, "slide_before"),
            slide(item, "slide_after"), "",
        )  # fmt: skip
    for item in result["contacts"]:
        if item["applied"]:
            table.add_row(
                item["id"], f"{item['start']}–{item['end']}", f"{item['confidence']:.2f}", "yes",
                slide(item, "slide_before"), slide(item, "slide_after"),
                str(item["clamped_frames"]),
            )  # fmt: skip
    summary = result["summary"]
    table.caption = (
        f"--apply {result['apply']}: {summary['contacts_locked']} contacts locked, "
        f"{summary['clamped_frames']} frames out of reach; skate findings "
        f"{summary['skate_findings_before']} → {summary['skate_findings_after']}; slides in % "
        "are of the estimated body height"
    )
    Console().print(table)


@feet_app.command("fix")
def feet_fix(
    take: Annotated[Path, typer.Argument(help="A BVH, keypoint or C3D take.")],
    output: Annotated[
        Path,
        typer.Option(
            "--output",
            "-o",
            help="The file to write (BVH; keypoints and markers: c3d, trc, csv, json, npy, npz).",
        ),
    ],
    apply: Annotated[
        str,
        typer.Option(
            "--apply",
            help="Which contacts to lock: confident (skate findings whose contact confidence is "
            "at least 0.5), skates (every skate finding's), all (every contact), none, or "
            "comma-separated ids from "
            "`mocapqa feet check --json` (skate findings, contacts).",
        ),
    ] = "confident",
    report_path: Annotated[
        Path | None, typer.Option("--report", help="Write the report JSON to this file.")
    ] = None,
    json_output: Annotated[bool, typer.Option("--json", help="Print the report JSON.")] = False,
    fps: FpsOption = None,
    length_unit: LengthUnitOption = None,
    mapping: MappingOption = None,
    root_translation: RootTranslationOption = "auto",
) -> None:
    """Lock planted feet (BVH: two-bone leg IK; keypoints and markers: pinned), blended, and
    write the take."""
    from mocapqa.core.motion import Motion
    from mocapqa.feet.fix import fix_feet
    from mocapqa.feet.fix_report import fix_report_json
    from mocapqa.io.atomic import write_text
    from mocapqa.pipeline.feet import check_take_feet, feet_params_of

    if not apply.strip() or (apply.strip().startswith(",") or apply.strip().endswith(",")):
        raise InputError(f"Expected --apply confident, skates, all, none or ids, got {apply!r}")
    read, roles = _read_take(take, fps, length_unit, mapping, root_translation)
    markers = not isinstance(read, Motion) and read.source_format == "c3d"
    params = feet_params_of(read)
    points, report, skipped = check_take_feet(read, roles, params)
    done = fix_feet(read, points, report, skipped, apply.strip(), params, mapping=roles)
    _, after, _ = check_take_feet(done.take, roles, params)
    _write_fixed(take, output, done.take, markers)
    fixed = {
        "path": str(take),
        "output": str(output),
        "apply": apply.strip(),
        **fix_report_json(
            points, report.contacts, report.findings, done.chosen, done.before.tolist(),
            done.after.tolist(), done.clamped.tolist(), done.miss.tolist(), after.findings,
            skipped,
        ),
    }  # fmt: skip
    text = json.dumps(fixed, indent=2)
    if report_path is not None:
        write_text(report_path, text + "\n")
    if json_output:
        typer.echo(text)
    else:
        _print_fix(take, output, fixed)


def _write_fixed(take: Path, output: Path, fixed: Motion | KeypointSequence, markers: bool) -> None:
    """Write a fixed take: BVH, or keypoints in the format of ``output``'s extension; a C3D
    take to a ``.c3d`` output through the C3D writer with the source's analogs, force plates
    and residuals carried through, every sample but the pinned ones as read."""
    import dataclasses

    from mocapqa.core.motion import Motion
    from mocapqa.io.bvh_write import write_bvh
    from mocapqa.io.formats import write_keypoints

    if isinstance(fixed, Motion):
        write_bvh(output, fixed)
    elif markers and output.suffix.lower() == ".c3d":
        from mocapqa.config import get_settings
        from mocapqa.io.c3d import read_c3d, write_c3d

        source = read_c3d(take, limits=get_settings().read_limits)
        write_c3d(output, dataclasses.replace(source, points=fixed), source=take)
    else:
        write_keypoints(output, fixed)
