"""``mocapqa render`` (stills, clips, contact sheets; the benchmark:
:mod:`mocapqa_bench.cli.bench_render`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
import typer
from rich.console import Console
from rich.progress import Progress

from mocapqa.cli.app import app
from mocapqa.cli.outputs import check_outputs, require_suffix, take_input
from mocapqa.cli.reading import read_input
from mocapqa.cli.report import TakeRun, analyze_take, sheet_tiles
from mocapqa.cli.roles import (
    MappingOption,
    RootTranslationOption,
    load_mapping,
    missing_roles,
    warn_missing,
)
from mocapqa.errors import InputError, NotFoundError, OptionError, ShapeError

if TYPE_CHECKING:
    from mocapqa.render.service import RenderService
    from mocapqa.render.still import StillOptions

__all__ = ["flagged_at", "parse_interval", "raw_run", "render"]

console = Console(highlight=False)


def parse_interval(text: str) -> tuple[str, int, int]:
    """Split ``JOINT:START-END`` (inclusive, 0-based frames) into its parts."""
    joint, _, frames = text.rpartition(":")
    start_text, _, end_text = frames.partition("-")
    try:
        start, end = int(start_text), int(end_text)
    except ValueError as e:
        raise InputError(f"Expected --interval JOINT:START-END, got {text!r}") from e
    if not joint or start > end:
        raise InputError(f"Expected --interval JOINT:START-END with START <= END, got {text!r}")
    return joint, start, end


def raw_run(
    path: Path,
    mapping: dict[str, str] | None = None,
    root_translation: Literal["auto", "add", "replace"] = "auto",
) -> TakeRun:
    """A take read without analysis: corrected is the raw take, no findings."""
    from mocapqa.core.motion import Motion
    from mocapqa.io.formats import require_frames
    from mocapqa.render.scene import track_from_keypoints, track_from_motion

    take = read_input(path, root_translation=root_translation)
    require_frames(take, path)
    summary: dict[str, object] = {"fps": 0.0}
    if isinstance(take, Motion):
        track = track_from_motion(take)
        summary["missing_roles"] = missing_roles(take.skeleton, mapping, warn=False)
    else:
        if mapping:
            raise InputError("Expected --mapping only for BVH input, got a keypoint take")
        track = track_from_keypoints(take)
    summary["fps"] = track.fps
    return TakeRun({"findings": [], "summary": summary}, track, track)


def flagged_at(run: TakeRun, frame: int) -> np.ndarray:
    """Joints with a finding covering ``frame``, as a ``(J,)`` boolean mask."""
    mask = np.zeros(len(run.raw.names), dtype=bool)
    for finding in run.analysis.get("findings", []):
        joint = finding.get("joint")
        if joint in run.raw.names and finding["start_frame"] <= frame <= finding["end_frame"]:
            mask[run.raw.names.index(joint)] = True
    return mask


@app.command()
def render(
    input_path: Annotated[Path, typer.Argument(metavar="IN", help="Take (BVH or keypoints).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="PNG, GIF or MP4 to write.")],
    frame: Annotated[int | None, typer.Option(help="Still of this frame (0-based).")] = None,
    interval: Annotated[
        str | None, typer.Option(help="Clip JOINT:START-END (inclusive), raw | corrected.")
    ] = None,
    contact_sheet: Annotated[
        bool, typer.Option("--contact-sheet", help="One tile per flagged interval.")
    ] = False,
    compare: Annotated[
        bool, typer.Option("--compare", help="Still as raw | corrected side by side.")
    ] = False,
    analyze: Annotated[
        bool, typer.Option("--analyze/--no-analyze", help="Run the checks to flag joints.")
    ] = True,
    up_axis: Annotated[
        str | None, typer.Option(help="Override the detected up axis (+y, -y, +z, ...).")
    ] = None,
    width: Annotated[int, typer.Option(help="Width of one view, px (16 to 8192).")] = 640,
    height: Annotated[int, typer.Option(help="Height of one view, px (16 to 8192).")] = 480,
    mapping: MappingOption = None,
    root_translation: RootTranslationOption = "auto",
) -> None:
    """Render a still (--frame), a clip (--interval) or a contact sheet (--contact-sheet)."""
    from mocapqa.io.atomic import write_bytes
    from mocapqa.render.service import RenderService

    options = _checked_request(
        input_path, output, frame, interval, contact_sheet, mapping, width, height
    )
    with Progress(console=console, transient=True) as bar, RenderService() as service:
        task = bar.add_task("reading", total=100)

        def step(percent: int, text: str) -> None:
            bar.update(task, completed=percent, description=text)

        run = _read_run(input_path, analyze, mapping, root_translation, up_axis, step)
        tick: Callable[[int, int], None] = lambda done, total: bar.update(  # noqa: E731
            task, completed=100 * done / total, description=f"rendering {done}/{total}"
        )
        if frame is not None:
            flags = flagged_at(run, frame) if 0 <= frame < run.raw.n_frames else None
            step(0, "rendering")
            if compare:
                data = service.side_by_side(run.raw, run.corrected, frame, flags, options)
            else:
                data = service.still(run.raw, frame, flags, options=options)
        elif interval is not None:
            data = _clip(service, run, interval, output, tick)
        else:
            tiles = sheet_tiles(run)
            if not tiles:
                raise InputError(
                    f"Expected flagged intervals for a contact sheet, got none in {input_path}"
                )
            data = service.contact_sheet(run.raw, tiles, run.corrected, progress=tick)
    write_bytes(output, data)
    console.print(f"{output} ({len(data) / 1e3:.0f} kB)")


def _checked_request(
    input_path: Path,
    output: Path,
    frame: int | None,
    interval: str | None,
    contact_sheet: bool,
    mapping: Path | None,
    width: int,
    height: int,
) -> StillOptions:
    """The image size as still options, once the request is found sound: one of --frame,
    --interval and --contact-sheet, an existing take, an output suffix that suits what is
    drawn, outputs that do not overwrite the inputs (all before the take is read).

    Raises
    ------
    OptionError
        For a width or height out of range.
    InputError
        For none or several of the three, or an output suffix that does not suit.
    NotFoundError
        For a take file that does not exist.
    """
    from mocapqa.render.clip import CLIP_FORMATS
    from mocapqa.render.still import StillOptions

    try:  # checked before the take is read
        options = StillOptions(width_px=width, height_px=height)
    except ShapeError as e:
        raise OptionError("--width/--height", str(e)) from e
    chosen = sum([frame is not None, interval is not None, contact_sheet])
    if chosen != 1:
        raise InputError(
            f"Expected exactly one of --frame, --interval, --contact-sheet, got {chosen}"
        )
    if not input_path.exists():
        raise NotFoundError(f"Expected an existing take file, got {input_path}")
    if interval is not None:
        clip = tuple(f".{kind}" for kind in CLIP_FORMATS)
        require_suffix("-o", output, clip, "a clip (--interval)")
    else:
        what = "a still (--frame)" if frame is not None else "a contact sheet"
        require_suffix("-o", output, (".png",), what)
    check_outputs({"-o": output}, [take_input(input_path), mapping])
    return options


def _read_run(
    input_path: Path,
    analyze: bool,
    mapping: Path | None,
    root_translation: Literal["auto", "add", "replace"],
    up_axis: str | None,
    step: Callable[[int, str], None],
) -> TakeRun:
    """The take, analysed or read as it is, with its up axis overridden when one is given;
    warns of the roles not found."""
    roles = load_mapping(mapping)
    if analyze:
        chosen_options = {"mapping": roles} if roles else None
        run = analyze_take(input_path, chosen_options, step, root_translation)
    else:
        run = raw_run(input_path, roles, root_translation)
    warn_missing(run.analysis.get("summary", {}).get("missing_roles") or [])
    if up_axis is not None:
        run = TakeRun(
            run.analysis,
            replace(run.raw, up_axis=up_axis),
            replace(run.corrected, up_axis=up_axis),
        )
    return run


def _clip(
    service: RenderService,
    run: TakeRun,
    interval: str,
    output: Path,
    tick: Callable[[int, int], None],
) -> bytes:
    """The clip of ``--interval`` (raw | corrected, its joint flagged), in the output's
    format."""
    joint, start, end = parse_interval(interval)
    if joint not in run.raw.names:
        raise InputError(f"Expected a joint of the take in --interval, got {joint!r}")
    fmt = output.suffix.lower().lstrip(".")
    flags = np.zeros(len(run.raw.names), dtype=bool)
    flags[run.raw.names.index(joint)] = True
    return service.clip(run.raw, start, end, run.corrected, flags, fmt, tick)
