"""``mocapqa info`` (what a file holds) and ``mocapqa convert`` (between formats).

Reading goes through :mod:`mocapqa.io.formats` (imported inside the commands, so that the CLI
starts fast); ``info`` prints a Rich table, or JSON with ``--json``. For BVH it lists the rig
roles found by :func:`mocapqa.core.rig.find_roles` and, as plainly, the roles it could not map.
A C3D is read with :func:`mocapqa.io.c3d.read_c3d` (its analogs, events and first frame are
listed too), and ``convert`` of a C3D to ``.c3d`` writes through the source, keeping its analogs,
force plates and other parameters.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import typer

from mocapqa.cli.app import app
from mocapqa.cli.reading import read_input
from mocapqa.cli.roles import (
    FpsOption,
    MappingOption,
    RootTranslationOption,
    load_mapping,
    missing_roles,
)
from mocapqa.errors import InputError, UnsupportedFormatError

if TYPE_CHECKING:
    from mocapqa.core.keypoints import KeypointSequence
    from mocapqa.core.motion import Motion
    from mocapqa.io.c3d import MarkerTake

__all__ = [
    "convert_command",
    "info_command",
    "keypoints_summary",
    "marker_take_summary",
    "motion_summary",
]


def motion_summary(
    motion: Motion,
    mapping: dict[str, str] | None = None,
    root_translation: Literal["auto", "add", "replace"] = "auto",
) -> dict[str, Any]:
    """What a BVH take holds, as a JSON-ready dict.

    Parameters
    ----------
    motion : Motion
        The take.
    mapping : dict, optional
        Role key → joint name, overriding the roles found from names and structure.
    root_translation : {"auto", "add", "replace"}
        What the reader was asked for, to explain the root reading.

    Returns
    -------
    dict
        Frames, fps, duration (s), joints, length unit, rotation orders (order → joint
        count), root translation mode and why, leading bind-pose frames (0 or 1, see
        :func:`mocapqa.kinematics.bindpose.leading_bind_pose`), roles found (role key → joint name),
        roles not mapped, and limb chains (``"left upper_arm: A > B > C"``).
    """
    from mocapqa.core.rig import find_roles, limb_chains
    from mocapqa.io.bvh_root import explain_root_translation
    from mocapqa.kinematics.bindpose import leading_bind_pose

    sk = motion.skeleton
    rig = find_roles(sk, mapping)
    orders: dict[str, int] = {}
    for j in range(sk.n_joints):
        order = sk.rotation_order(j)
        if order:
            orders[order] = orders.get(order, 0) + 1
    chains = []
    for chain in limb_chains(rig):
        names = [sk.names[chain.parent], sk.names[chain.child]]
        if chain.grandchild is not None:
            names.append(sk.names[chain.grandchild])
        chains.append(f"{chain.side} {chain.segment}: {' > '.join(names)}")
    return {
        "format": "bvh",
        "frames": motion.n_frames,
        "fps": motion.fps,
        "duration_s": motion.duration_s,
        "joints": sk.n_joints,
        "end_sites": len(sk.end_sites),
        "channels": sum(len(c) for c in sk.channels),
        "length_unit": sk.length_unit,
        "rotation_orders": orders,
        "root_translation": sk.root_translation,
        "root_translation_reason": explain_root_translation(motion, root_translation),
        "bind_pose_frames": leading_bind_pose(motion.quats),
        "roles": {key: sk.names[j] for key, j in sorted(rig.roles.items())},
        "unmapped_roles": list(rig.unmapped),
        "limb_chains": chains,
        "joint_names": list(sk.names),
    }


def keypoints_summary(seq: KeypointSequence, format_name: str) -> dict[str, Any]:
    """What a keypoint take holds, as a JSON-ready dict.

    Returns
    -------
    dict
        Format, frames, fps, duration (s), keypoints, dimensions, length unit, the share
        of missing frame × keypoint values (0–1), what the reader assumed (frame rate, unit,
        frame numbers) and the keypoint names.
    """
    return {
        "format": format_name,
        "frames": seq.n_frames,
        "fps": seq.fps,
        "duration_s": seq.duration_s,
        "keypoints": seq.n_keypoints,
        "dimensions": seq.n_dims,
        "length_unit": seq.length_unit,
        "missing_fraction": seq.missing_fraction,
        "assumptions": list(seq.assumptions),
        "keypoint_names": list(seq.names),
    }


def marker_take_summary(take: MarkerTake) -> dict[str, Any]:
    """What a C3D take holds, as a JSON-ready dict.

    Returns
    -------
    dict
        Format, reader ("ezc3d" or "py-c3d"), frames, fps, duration (s), markers, length
        unit, first frame (1-based, as stored), the share of missing frame × marker samples
        (0–1), analog channels and their rate (None without channels), events (label, context,
        time in s, 0-based frame), what the reader assumed, and the marker names.
    """
    seq = take.points
    return {
        "format": "c3d",
        "reader": take.reader,
        "frames": seq.n_frames,
        "fps": seq.fps,
        "duration_s": seq.duration_s,
        "markers": seq.n_keypoints,
        "length_unit": seq.length_unit,
        "first_frame": take.first_frame,
        "missing_fraction": seq.missing_fraction if seq.n_keypoints else 0.0,
        "analog_channels": len(take.analog_labels),
        "analog_rate": take.analog_rate,
        "events": [
            {"label": e.label, "context": e.context, "time_s": e.time_s, "frame": e.frame}
            for e in take.events
        ],
        "assumptions": list(seq.assumptions),
        "marker_names": list(seq.names),
    }


def _read_marker_take(path: Path) -> MarkerTake:
    from mocapqa.config import get_settings
    from mocapqa.io.c3d import read_c3d

    return read_c3d(path, get_settings().read_limits)


def _print_table(path: Path, summary: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(show_header=False)
    table.add_column("field", style="bold")
    table.add_column("value", overflow="fold")
    table.add_row("file", str(path))
    for key, value in summary.items():
        if key in ("joint_names", "keypoint_names", "marker_names"):
            continue
        if key == "fps" or key == "duration_s":
            text = f"{value:.6g}"
        elif key == "missing_fraction":
            text = f"{100 * value:.2f} %"
        elif key == "rotation_orders":
            text = ", ".join(f"{order} ×{count}" for order, count in value.items()) or "none"
        elif key == "roles":
            text = "\n".join(f"{role}: {joint}" for role, joint in value.items()) or "none"
        elif key == "unmapped_roles":
            text = f"[yellow]{', '.join(value)}[/]" if value else "none (all roles mapped)"
        elif key == "bind_pose_frames":
            text = (
                "frame 0 (a T-pose, not motion: filters start on frame 1, twist detection skips "
                "the step into it)"
                if value
                else "none"
            )
        elif key == "events":
            text = (
                "\n".join(
                    f"{e['label']} {e['context']} {e['time_s']:.3f} s (frame {e['frame']})"
                    for e in value
                )
                or "none"
            )
        elif key == "analog_rate":
            text = "none" if value is None else f"{value:.6g}"
        elif key == "limb_chains":
            text = "\n".join(value) or "none"
        elif key == "assumptions":
            text = "\n".join(f"[yellow]{v}[/]" for v in value) or "none (all stored in the file)"
        else:
            text = str(value)
        table.add_row(key.replace("_", " "), text)
    Console().print(table)


@app.command("info")
def info_command(
    file: Annotated[Path, typer.Argument(help="A BVH, C3D or keypoint file (or OpenPose folder).")],
    json_output: Annotated[bool, typer.Option("--json", help="Print JSON instead.")] = False,
    fps: FpsOption = None,
    mapping: MappingOption = None,
    root_translation: RootTranslationOption = "auto",
) -> None:
    """Show what a take holds: frames, rate, joints or keypoints, units, rig roles."""
    from mocapqa.core.motion import Motion
    from mocapqa.io.formats import check_fps, detect_format

    if fps is not None:
        check_fps(fps, "--fps")
    roles = load_mapping(mapping)
    format_name = detect_format(file)
    if format_name == "c3d":
        if roles is not None:
            raise InputError("Expected --mapping only for BVH input, got a c3d file")
        summary = marker_take_summary(_read_marker_take(file))
        if json_output:
            typer.echo(json.dumps({"path": str(file), **summary}, indent=2))
        else:
            _print_table(file, summary)
        return
    take = read_input(file, fps=fps, number_reader="auto", root_translation=root_translation)
    if isinstance(take, Motion):
        summary = motion_summary(take, roles, root_translation)
        missing_roles(take.skeleton, roles)
    else:
        if roles is not None:
            raise InputError(f"Expected --mapping only for BVH input, got a {format_name} file")
        summary = keypoints_summary(take, format_name)
    if json_output:
        typer.echo(json.dumps({"path": str(file), **summary}, indent=2))
    else:
        _print_table(file, summary)


def _check_keypoint_output(mapped: bool, output: Path, source: str) -> None:
    """Refuse ``--mapping`` for a keypoint or marker ``source``, and an output that is not a
    keypoint format."""
    from mocapqa.io.formats import KEYPOINT_WRITE_FORMATS

    if mapped:
        raise InputError(f"Expected --mapping only for BVH input, got {source}")
    if output.suffix.lower().lstrip(".") not in KEYPOINT_WRITE_FORMATS:
        raise UnsupportedFormatError(
            f"Expected a keypoint output among {', '.join(KEYPOINT_WRITE_FORMATS)}, "
            f"got {output.name!r}"
        )


@app.command("convert")
def convert_command(
    source: Annotated[Path, typer.Argument(help="Input take (BVH or keypoints).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output file.")],
    fps: Annotated[
        float | None, typer.Option(help="Frames per second, for inputs that do not store it.")
    ] = None,
    precision: Annotated[int, typer.Option(help="Decimal places of BVH channel values.")] = 6,
    mapping: MappingOption = None,
) -> None:
    """Convert a take: BVH to BVH, keypoints and C3D between TRC, CSV, NPY, NPZ, JSON and C3D."""
    from mocapqa.cli.outputs import check_outputs, take_input
    from mocapqa.core.motion import Motion
    from mocapqa.io.bvh_write import write_bvh
    from mocapqa.io.c3d import write_c3d
    from mocapqa.io.formats import (
        check_fps,
        detect_format,
        require_frames,
        write_keypoints,
    )

    if fps is not None:
        check_fps(fps, "--fps")
    if not 0 <= precision <= 15:
        raise InputError(f"Expected --precision between 0 and 15, got {precision}")
    suffix = output.suffix.lower().lstrip(".")
    check_outputs({"-o": output}, [take_input(source), mapping], sidecars=True)
    roles = load_mapping(mapping)
    if detect_format(source) == "c3d":
        _check_keypoint_output(roles is not None, output, "a c3d file")
        markers = _read_marker_take(source)
        if suffix == "c3d":
            # Through the source (analogs, force plates, events kept) when ezc3d reads it.
            write_c3d(output, markers, source if markers.reader == "ezc3d" else None)
        else:
            require_frames(markers.points, source)
            write_keypoints(output, markers.points)
        typer.echo(f"wrote {output} ({suffix}, {markers.points.n_frames} frames)")
        return
    take = read_input(source, fps=fps, number_reader="auto")
    if isinstance(take, Motion):
        missing_roles(take.skeleton, roles)
        if suffix != "bvh":
            raise UnsupportedFormatError(
                f"Expected a .bvh output for a BVH input, got {output.name!r}"
            )
        write_bvh(output, take, precision=precision)
    else:
        _check_keypoint_output(roles is not None, output, "a keypoint take")
        write_keypoints(output, take)
    typer.echo(f"wrote {output} ({suffix}, {take.n_frames} frames)")
