"""``mocapqa filter`` (the benchmark: :mod:`mocapqa_bench.cli.bench_filters`)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console

from mocapqa.cli.app import app
from mocapqa.cli.outputs import check_outputs, require_suffix, take_input
from mocapqa.cli.reading import read_input
from mocapqa.cli.roles import FpsOption, MappingOption, load_mapping, missing_roles
from mocapqa.errors import InputError

__all__ = ["filter_command", "parse_overrides"]

console = Console(highlight=False)


def parse_overrides(items: list[str]) -> dict[str, str]:
    """``["k=v", ...]`` → ``{"k": "v"}``; raises InputError on an item without ``=``."""
    out: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise InputError(f"Expected --param NAME=VALUE, got {item!r}")
        out[key.strip()] = value.strip()
    return out


@app.command("filter")
def filter_command(
    input_path: Annotated[Path, typer.Argument(help="Keypoint file (any format) or BVH.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output file.")],
    method: Annotated[str, typer.Option(help="Filter method (see the registry).")] = "",
    preset: Annotated[str, typer.Option(help="Parameter preset: default or note.")] = "default",
    param: Annotated[
        list[str] | None, typer.Option(help="Override, NAME=VALUE (repeatable).")
    ] = None,
    report: Annotated[Path | None, typer.Option(help="Write a JSON report here.")] = None,
    fps: FpsOption = None,
    mapping: MappingOption = None,
) -> None:
    """Filter a keypoint file or the rotations of a BVH take."""
    from mocapqa.core.motion import Motion
    from mocapqa.filters.apply import filter_keypoints, filter_motion
    from mocapqa.filters.registry import FILTERS
    from mocapqa.io.atomic import write_text
    from mocapqa.io.bvh_write import write_bvh
    from mocapqa.io.formats import (
        KEYPOINT_WRITE_FORMATS,
        check_fps,
        require_frames,
        write_keypoints,
    )
    from mocapqa.metrics.smoothness import MIN_FRAMES, lag_frames, mean_abs_jerk
    from mocapqa.pipeline.options import DEFAULT_OPTIONS

    if fps is not None:
        check_fps(fps, "--fps")
    overrides = parse_overrides(param or [])
    check_outputs(
        {"-o": output, "--report": report}, [take_input(input_path), mapping], sidecars=True
    )
    roles = load_mapping(mapping)
    take = read_input(input_path, fps=fps)
    require_frames(take, input_path)
    summary: dict[str, Any]
    if roles is not None and not isinstance(take, Motion):
        raise InputError("Expected --mapping only for BVH input, got a keypoint take")
    if isinstance(take, Motion):
        require_suffix("-o", output, (".bvh",), "a BVH input's filtered take")
    else:
        formats = tuple(f".{kind}" for kind in KEYPOINT_WRITE_FORMATS)
        require_suffix("-o", output, formats, "filtered keypoints")
    if isinstance(take, Motion):
        missing_roles(take.skeleton, roles)
        method = method or "quat-pd"
        if preset != "default":
            raise InputError(f"Expected preset 'default' for rotation filters, got {preset!r}")
        out_motion = filter_motion(take, method, overrides)
        write_bvh(output, out_motion)
        summary = {"method": method, "frames": take.n_frames, "joints": take.skeleton.n_joints}
    else:
        method = method or "adaptive"
        if method not in FILTERS:
            raise InputError(f"Expected --method in {sorted(FILTERS)}, got {method!r}")
        result = filter_keypoints(take, method, preset, overrides)
        # The report is made before anything is written: a metric that fails must not leave
        # an output behind and then exit with an error.
        summary = result.to_json(max_points=DEFAULT_OPTIONS.max_points)
        per_key = []
        for k, name in enumerate(take.names):
            raw, out = take.positions[:, k], result.sequence.positions[:, k]
            per_key.append(
                {
                    "keypoint": name,
                    "jerk_raw": _available(mean_abs_jerk(raw, take.fps)),
                    "jerk_filtered": _available(mean_abs_jerk(out, take.fps)),
                    "lag_frames_vs_input": _available(lag_frames(raw, out)),
                }
            )
        summary["per_keypoint"] = per_key
        summary["notes"] = _metric_notes(take.n_frames, MIN_FRAMES, per_key)
        write_keypoints(output, result.sequence)
    if report is not None:
        write_text(report, json.dumps(summary, indent=1, default=str, allow_nan=True))
    console.print(f"filtered {input_path} with {method} → {output}")
    for note in summary.get("notes", []):
        console.print(note)


def _available(value: float) -> float | None:
    """A metric for the report: None (JSON null, "not available") when it is not finite."""
    return value if math.isfinite(value) else None


def _metric_notes(n_frames: int, min_frames: int, rows: list[dict[str, Any]]) -> list[str]:
    """What the report's per-keypoint metrics could not give, in words (empty: all given)."""
    if n_frames < min_frames:
        return [
            f"jerk and lag not available (null): the take has {n_frames} frame(s), they need "
            f"at least {min_frames}"
        ]
    if any(value is None for row in rows for value in row.values()):
        return ["a null jerk or lag is not available: the keypoint has too few samples or is still"]
    return []
