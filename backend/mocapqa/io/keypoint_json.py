"""The generic keypoint JSON form.

Conventions
-----------
* ``{"fps": 30, "unit": "m", "n_dims": 3, "keypoints": [names], "frames": [[[x, y, z, c], ...],
  ...]}``: one list per frame, one entry per keypoint. An entry is ``[x, y]``, ``[x, y, z]`` or
  ``[x, y, z, c]`` (confidence 1.0 when absent); ``null`` (as a whole entry or a coordinate) is
  missing. ``NaN`` is accepted as missing; infinity is an error.
* ``n_dims`` is 2 when given so or when every entry has two coordinates; otherwise 3.
* ``fps`` is the caller's, else the file's, else an error; ``unit`` is the caller's
  ``length_unit``, else the file's, else "unknown".
* ``times`` (optional): the time of each frame, seconds, one number (or ``null``, unknown) per
  frame. The writer writes it when the sequence has the source's times (a TRC's ``Time``
  column, which starts at ``1 / DataRate`` in Pose2Sim files), so a take converted to JSON and
  read back keeps its start time; without it frames are at ``frame / fps`` from 0.
* The writer uses ``null`` for missing values and Python's shortest float repr, so a written
  file reads back exactly.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.atomic import write_text
from mocapqa.io.keypoint_input import (
    build_keypoint_sequence,
    parse_json,
    read_file_bytes,
    resolve_fps,
    resolve_length_unit,
)

__all__ = [
    "format_keypoint_json",
    "parse_keypoint_json",
    "read_keypoint_json",
    "write_keypoint_json",
]


def _number(value: Any, path: str, field: str) -> float:
    if value is None:
        return math.nan
    if isinstance(value, bool) or not isinstance(value, int | float) or math.isinf(value):
        raise ParseError(
            f"Expected a finite number or null, got {str(value)[:20]!r}", path, field=field
        )
    return float(value)


def _point(entry: Any, path: str, field: str) -> tuple[list[float], float, int]:
    if entry is None:
        return [math.nan] * 3, 0.0, 0
    if not isinstance(entry, list) or not 2 <= len(entry) <= 4:
        raise ParseError("Expected [x, y], [x, y, z] or [x, y, z, c]", path, field=field)
    values = [_number(v, path, f"{field}[{i}]") for i, v in enumerate(entry)]
    xyz = values[:3] + [0.0] * (3 - min(len(values), 3))
    conf = values[3] if len(values) == 4 else 1.0
    if not (math.isnan(conf) or 0.0 <= conf <= 1.0):
        raise ParseError(f"Expected confidence in [0, 1], got {conf}", path, field=f"{field}[3]")
    return xyz, 0.0 if math.isnan(conf) else conf, len(values)


def _times(value: Any, n_frames: int, path: str) -> FloatArray | None:
    """The ``times`` member: None when absent, else one number (NaN for null) per frame."""
    if value is None:
        return None
    if not isinstance(value, list) or len(value) != n_frames:
        got = f"{len(value)} value(s)" if isinstance(value, list) else f"{str(value)[:20]!r}"
        raise ParseError(
            f"Expected a list of {n_frames} times (one per frame), got {got}", path, field="times"
        )
    return np.array([_number(v, path, f"times[{i}]") for i, v in enumerate(value)])


def parse_keypoint_json(
    data: bytes | str,
    path: str | Path = "<keypoints.json>",
    fps: float | None = None,
    length_unit: str | None = None,
) -> KeypointSequence:
    """Parse the generic keypoint JSON form.

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.
    fps : float, optional
        Frames per second; else the file's ``fps``; else an error.
    length_unit : str, optional
        Unit; else the file's ``unit``; else "unknown".

    Returns
    -------
    KeypointSequence
        Positions ``(F, K, 3)`` and confidence ``(F, K)``.

    Raises
    ------
    ParseError
        On invalid JSON (with its line) or a wrong structure (with the field).
    """
    path = str(path)
    document = parse_json(data, path)
    if not isinstance(document, dict):
        raise ParseError("Expected a JSON object", path)
    names = document.get("keypoints")
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise ParseError("Expected a list of keypoint names", path, field="keypoints")
    frames = document.get("frames")
    if not isinstance(frames, list):
        raise ParseError("Expected a list of frames", path, field="frames")
    positions = np.full((len(frames), len(names), 3), np.nan)
    confidence = np.zeros((len(frames), len(names)))
    widths: set[int] = set()
    for i, frame in enumerate(frames):
        if not isinstance(frame, list) or len(frame) != len(names):
            raise ParseError(f"Expected a list of {len(names)} points", path, field=f"frames[{i}]")
        for k, entry in enumerate(frame):
            positions[i, k], confidence[i, k], width = _point(entry, path, f"frames[{i}][{k}]")
            widths.add(width)
    file_fps = document.get("fps")
    if file_fps is not None:
        file_fps = _number(file_fps, path, "fps")
    unit = document.get("unit")
    if unit is not None and not isinstance(unit, str):
        raise ParseError(f"Expected a unit string, got {str(unit)[:20]!r}", path, field="unit")
    n_dims = document.get("n_dims", 2 if widths <= {0, 2} and 2 in widths else 3)
    if n_dims not in (2, 3) or isinstance(n_dims, bool):
        raise ParseError(f"Expected n_dims 2 or 3, got {str(n_dims)[:20]!r}", path, field="n_dims")
    times = _times(document.get("times"), len(frames), path)
    notes: list[str] = []
    rate = resolve_fps(fps, file_fps, None, path, "JSON", notes)
    unit = resolve_length_unit(length_unit or unit, "unknown", path, notes)
    return build_keypoint_sequence(
        path, tuple(names), positions, confidence, rate,
        length_unit=unit, n_dims=int(n_dims), source_format="json", assumptions=notes,
        times=times,
    )  # fmt: skip


def read_keypoint_json(
    path: str | Path, fps: float | None = None, length_unit: str | None = None
) -> KeypointSequence:
    """Read a generic keypoint JSON file. See :func:`parse_keypoint_json`."""
    return parse_keypoint_json(read_file_bytes(path), path, fps, length_unit)


def format_keypoint_json(seq: KeypointSequence) -> str:
    """Format a sequence as the generic keypoint JSON form.

    Parameters
    ----------
    seq : KeypointSequence
        The data.

    Returns
    -------
    str
        Compact JSON with one frame per line; missing points are ``null``. The sequence's
        ``times``, when it has them, follow the frames (``null`` where unknown).
    """
    head = json.dumps(
        {
            "fps": seq.fps,
            "unit": seq.length_unit,
            "n_dims": seq.n_dims,
            "keypoints": list(seq.names),
        }
    )
    rows = []
    for frame in range(seq.n_frames):
        points: list[Any] = []
        for k in range(seq.n_keypoints):
            xyz = seq.positions[frame, k]
            if np.any(np.isnan(xyz)):
                points.append(None)
            else:
                points.append([float(v) for v in xyz] + [float(seq.confidence[frame, k])])
        rows.append(json.dumps(points, allow_nan=False))
    tail = ""
    if seq.times is not None:
        times = [float(t) if math.isfinite(t) else None for t in seq.times.tolist()]
        tail = ',\n"times": ' + json.dumps(times, allow_nan=False)
    return head[:-1] + ', "frames": [\n' + ",\n".join(rows) + "\n]" + tail + "}\n"


def write_keypoint_json(path: str | Path, seq: KeypointSequence) -> None:
    """Write a sequence as generic keypoint JSON, whole or not at all (:mod:`mocapqa.io.atomic`).

    Parameters
    ----------
    path, seq : str or Path, KeypointSequence
        The destination file, and the data.
    """
    write_text(path, format_keypoint_json(seq))
