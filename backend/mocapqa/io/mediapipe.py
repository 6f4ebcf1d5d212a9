"""MediaPipe Pose (BlazePose) landmarks: long CSV, JSON exports and the pbtxt golden file.

Conventions
-----------
* 33 landmarks named as MediaPipe's ``PoseLandmark`` enum (``NOSE`` ... ``RIGHT_FOOT_INDEX``).
* Long CSV ``frame_number,landmark,x,y,z[,visibility]``: world landmarks in metres (origin at
  the hip centre, y down), recorded as an assumption unless ``length_unit`` is given. Without a
  visibility column, confidence is 1.0. Landmarks may be given by name or by index. Frames
  missing from the file are missing in the sequence.
* JSON: either a list of frames, each a list of 33 ``{"x", "y", "z", "visibility"}`` objects,
  or ``{"frames": [{"landmarks": [...]}, ...]}`` (an optional top-level ``fps``). The unit is
  not stored: "unknown" unless ``length_unit`` is given. ``visibility`` is the confidence
  (1.0 when absent); an empty landmark list or ``null`` marks a frame without detection.
* pbtxt: one ``LandmarksDetectionResult`` frame; the ``landmarks`` block (normalised image
  coordinates, unit "normalized") is read, or ``world_landmarks`` (metres) when it is the only
  one. ``visibility`` is the confidence.
* No format stores a frame rate except the JSON ``fps`` field: ``fps`` defaults to 30 and the
  default is recorded in ``assumptions``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.guards import ReadLimits
from mocapqa.io.keypoint_input import (
    build_keypoint_sequence,
    decode_text,
    float_from_text,
    parse_json,
    read_file_bytes,
    resolve_fps,
    resolve_length_unit,
)
from mocapqa.io.keypoint_layouts import MEDIAPIPE_33_NAMES
from mocapqa.io.keypoint_rows import KeypointRow, dense_keypoints

__all__ = [
    "MEDIAPIPE_DEFAULT_FPS",
    "parse_mediapipe_csv",
    "parse_mediapipe_json",
    "parse_mediapipe_pbtxt",
    "read_mediapipe_csv",
    "read_mediapipe_json",
    "read_mediapipe_pbtxt",
]

# Frame rate assumed (and recorded) when the caller gives none.
MEDIAPIPE_DEFAULT_FPS = 30.0
_N = len(MEDIAPIPE_33_NAMES)
_INDEX = {name: i for i, name in enumerate(MEDIAPIPE_33_NAMES)}


def _landmark_index(text: str, path: str, line: int) -> int:
    key = text.strip().upper()
    if key in _INDEX:
        return _INDEX[key]
    if key.isdigit() and int(key) < _N:
        return int(key)
    raise ParseError(
        f"Expected a MediaPipe landmark name, got {text[:40]!r}", path, line, "landmark"
    )


def _frame_number(text: str, path: str, line: int) -> int:
    value = float_from_text(text, path, line, "frame_number")
    if not (math.isfinite(value) and value == int(value) and value >= 0):
        raise ParseError(f"Expected a frame number >= 0, got {text[:20]!r}", path, line)
    return int(value)


def _landmark_rows(lines: list[str], path: str) -> list[KeypointRow]:
    """The landmark rows of a long MediaPipe CSV below its header line.

    A row's line, named when its (frame, landmark) repeats, is its place among the rows + 1.
    """
    header = [c.strip().lower() for c in lines[0].split(",")] if lines else []
    required = ["frame_number", "landmark", "x", "y", "z"]
    if any(name not in header for name in required):
        raise ParseError(f"Expected header with {','.join(required)}, got {header[:8]}", path, 1)
    cols = [header.index(name) for name in required]
    vis_col = header.index("visibility") if "visibility" in header else None
    rows: list[KeypointRow] = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        cells = line.split(",")
        if len(cells) != len(header):
            raise ParseError(f"Expected {len(header)} cells, got {len(cells)}", path, number)
        frame = _frame_number(cells[cols[0]], path, number)
        landmark = _landmark_index(cells[cols[1]], path, number)
        xyz = [
            float_from_text(cells[c], path, number, n)
            for c, n in zip(cols[2:], "xyz", strict=False)
        ]
        vis = 1.0 if vis_col is None else float_from_text(cells[vis_col], path, number)
        rows.append((frame, landmark, xyz, 0.0 if math.isnan(vis) else vis, len(rows) + 2))
    return rows


def parse_mediapipe_csv(
    data: bytes | str,
    path: str | Path = "<mediapipe.csv>",
    fps: float | None = None,
    length_unit: str | None = None,
    limits: ReadLimits | None = None,
) -> KeypointSequence:
    """Parse the long MediaPipe CSV ``frame_number,landmark,x,y,z[,visibility]``.

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.
    fps : float, optional
        Frames per second (not stored in the file); default 30, recorded.
    length_unit : str, optional
        Unit of x, y, z; default "m" (world landmarks), recorded.
    limits : ReadLimits, optional
        Refuse a take spanning more frames × 33 than ``limits.max_frame_points`` before its
        arrays are made (the frame numbers can claim far more frames than the rows hold).

    Returns
    -------
    KeypointSequence
        Positions ``(F, 33, 3)``; F spans the first to the last frame number.

    Raises
    ------
    ParseError
        On a wrong header, bad cells, unknown landmarks or duplicate rows (file and line).
    TooLargeError
        Beyond ``limits``.
    """
    path = str(path)
    lines = decode_text(data, path).splitlines()
    rows = _landmark_rows(lines, path)
    if not rows:
        raise ParseError("Expected at least one landmark row, got none", path, len(lines))
    dense = dense_keypoints(
        rows,
        _N,
        path,
        limits,
        lambda frame, landmark: (
            f"Expected one row per frame and landmark, got a repeated "
            f"{MEDIAPIPE_33_NAMES[landmark]} in frame {frame}"
        ),
    )
    notes: list[str] = []
    unit = resolve_length_unit(length_unit, "m", path, notes)
    rate = resolve_fps(fps, None, MEDIAPIPE_DEFAULT_FPS, path, "MediaPipe CSV", notes)
    return build_keypoint_sequence(
        path, MEDIAPIPE_33_NAMES, dense.positions, dense.confidence, rate,
        length_unit=unit, n_dims=3, source_format="mediapipe-csv", assumptions=notes,
    )  # fmt: skip


def read_mediapipe_csv(
    path: str | Path,
    fps: float | None = None,
    length_unit: str | None = None,
    limits: ReadLimits | None = None,
) -> KeypointSequence:
    """Read a long MediaPipe CSV. See :func:`parse_mediapipe_csv`."""
    return parse_mediapipe_csv(read_file_bytes(path), path, fps, length_unit, limits)


def _landmark_value(item: dict[str, Any], key: str, path: str, field: str) -> float:
    value = item.get(key)
    if value is None:
        return math.nan if key != "visibility" else 1.0
    if isinstance(value, bool) or not isinstance(value, int | float) or math.isinf(value):
        raise ParseError(f"Expected a finite number, got {str(value)[:20]!r}", path, field=field)
    return float(value)


def _frames_of(document: Any, path: str) -> tuple[list[Any], Any]:
    if isinstance(document, list):
        for i, frame in enumerate(document):
            if frame is not None and not isinstance(frame, list):
                raise ParseError(
                    f"Expected a list of landmarks, got {type(frame).__name__}",
                    path,
                    field=f"frames[{i}]",
                )
        return document, None
    if isinstance(document, dict) and isinstance(document.get("frames"), list):
        frames = []
        for i, frame in enumerate(document["frames"]):
            if isinstance(frame, dict):
                frame = frame.get("landmarks", frame.get("pose_landmarks"))
            if frame is not None and not isinstance(frame, list):
                raise ParseError("Expected a landmark list", path, field=f"frames[{i}].landmarks")
            frames.append(frame)
        return frames, document.get("fps")
    raise ParseError("Expected a list of frames or {'frames': [...]}", path, field="frames")


def parse_mediapipe_json(
    data: bytes | str,
    path: str | Path = "<mediapipe.json>",
    fps: float | None = None,
    length_unit: str | None = None,
) -> KeypointSequence:
    """Parse a MediaPipe landmark JSON export (see the module notes for the two layouts).

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.
    fps : float, optional
        Frames per second; else the file's ``fps``; else 30, recorded.
    length_unit : str, optional
        Unit of the coordinates; "unknown" when not given.

    Returns
    -------
    KeypointSequence
        Positions ``(F, 33, 3)``, visibility as confidence.

    Raises
    ------
    ParseError
        On invalid JSON (line) or a wrong structure (field).
    """
    path = str(path)
    document = parse_json(data, path)
    frames, file_fps = _frames_of(document, path)
    if not frames:
        raise ParseError("Expected at least one frame, got none", path, field="frames")
    positions = np.full((len(frames), _N, 3), np.nan)
    confidence = np.zeros((len(frames), _N))
    for i, frame in enumerate(frames):
        if not frame:
            continue
        if len(frame) != _N:
            raise ParseError(
                f"Expected {_N} landmarks, got {len(frame)}", path, field=f"frames[{i}]"
            )
        for j, item in enumerate(frame):
            field = f"frames[{i}][{j}]"
            if not isinstance(item, dict):
                raise ParseError("Expected an {x, y, z, visibility} object", path, field=field)
            positions[i, j] = [_landmark_value(item, k, path, f"{field}.{k}") for k in "xyz"]
            confidence[i, j] = _landmark_value(item, "visibility", path, f"{field}.visibility")
    if file_fps is not None and (
        isinstance(file_fps, bool) or not isinstance(file_fps, int | float)
    ):
        raise ParseError(f"Expected a number, got {str(file_fps)[:20]!r}", path, field="fps")
    notes: list[str] = []
    unit = resolve_length_unit(length_unit, "unknown", path, notes)
    rate = resolve_fps(fps, file_fps, MEDIAPIPE_DEFAULT_FPS, path, "MediaPipe JSON", notes)
    return build_keypoint_sequence(
        path, MEDIAPIPE_33_NAMES, positions, confidence, rate,
        length_unit=unit, n_dims=3, source_format="mediapipe-json", assumptions=notes,
    )  # fmt: skip


def read_mediapipe_json(
    path: str | Path, fps: float | None = None, length_unit: str | None = None
) -> KeypointSequence:
    """Read a MediaPipe landmark JSON export. See :func:`parse_mediapipe_json`."""
    return parse_mediapipe_json(read_file_bytes(path), path, fps, length_unit)


_PBTXT_TOKEN = re.compile(
    r"\s*(?:#[^\n]*\n?|([A-Za-z_][\w]*)\s*:\s*(\S+)|([A-Za-z_]\w*)\s*\{|(\}))"
)


_SPACE = re.compile(r"\s*")
_PBTXT_MAX_DEPTH = 8
"""Deepest block nesting a landmarks file may have (MediaPipe's own use two)."""


def _pbtxt_blocks(text: str, path: str) -> dict[str, list[list[dict[str, float]]]]:
    blocks: dict[str, list[list[dict[str, float]]]] = {}
    stack: list[str] = []
    current: dict[str, float] | None = None
    pos = 0
    line, counted = 1, 0  # the line of ``pos``, counted up to ``counted`` (linear in the text)
    while pos < len(text):
        match = _PBTXT_TOKEN.match(text, pos)
        start = _SPACE.match(text, pos).end()  # type: ignore[union-attr]  # always matches
        line += text.count("\n", counted, start)  # the line of the token itself
        counted = start
        if match is None or match.end() == pos:
            if text[pos:].strip():
                raise ParseError(
                    f"Expected pbtxt, got {text[pos : pos + 20].strip()!r}", path, line
                )
            break
        pos = match.end()
        key, value, opened, closed = match.groups()
        if opened:
            if len(stack) >= _PBTXT_MAX_DEPTH:
                deepest = f"Expected blocks nested at most {_PBTXT_MAX_DEPTH} deep, got deeper"
                raise ParseError(deepest, path, line)
            stack.append(opened)
            if len(stack) == 1:
                blocks.setdefault(opened, []).append([])
            elif len(stack) == 2:
                current = {}
        elif closed:
            if not stack:
                raise ParseError("Expected a block to close, got '}'", path, line)
            if len(stack) == 2 and current is not None:
                blocks[stack[0]][-1].append(current)
                current = None
            stack.pop()
        elif key and current is not None and len(stack) == 2:
            current[key] = float_from_text(value, path, line, key)
    if stack:
        raise ParseError(f"Expected '}}' closing {stack[-1]!r}, got end of file", path)
    return blocks


def parse_mediapipe_pbtxt(
    data: bytes | str, path: str | Path = "<pose.pbtxt>", fps: float | None = None
) -> KeypointSequence:
    """Parse a single-frame MediaPipe ``LandmarksDetectionResult`` in protobuf text format.

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.
    fps : float, optional
        Frames per second for the one frame; default 30, recorded.

    Returns
    -------
    KeypointSequence
        One frame of 33 landmarks, visibility as confidence.

    Raises
    ------
    ParseError
        On malformed text or a landmark count other than 33.
    """
    path = str(path)
    blocks = _pbtxt_blocks(decode_text(data, path), path)
    if "landmarks" in blocks:
        key, unit = "landmarks", "normalized"
    elif "world_landmarks" in blocks:
        key, unit = "world_landmarks", "m"
    else:
        raise ParseError("Expected a 'landmarks' block, got none", path, field="landmarks")
    items = blocks[key][0]
    if len(items) != _N:
        raise ParseError(f"Expected {_N} landmarks, got {len(items)}", path, field=key)
    positions = np.array([[item.get(k, math.nan) for k in "xyz"] for item in items])[None]
    confidence = np.array([item.get("visibility", 1.0) for item in items])[None]
    notes: list[str] = []
    rate = resolve_fps(fps, None, MEDIAPIPE_DEFAULT_FPS, path, "MediaPipe pbtxt", notes)
    return build_keypoint_sequence(
        path, MEDIAPIPE_33_NAMES, positions, confidence, rate,
        length_unit=unit, n_dims=3, source_format="mediapipe-pbtxt", assumptions=notes,
    )  # fmt: skip


def read_mediapipe_pbtxt(path: str | Path, fps: float | None = None) -> KeypointSequence:
    """Read a MediaPipe pbtxt golden file. See :func:`parse_mediapipe_pbtxt`."""
    return parse_mediapipe_pbtxt(read_file_bytes(path), path, fps)
