"""The documented long keypoint CSV: one row per frame and keypoint.

Conventions
-----------
* Header ``frame,time,keypoint,x,y,z,confidence``; ``frame``, ``keypoint``, ``x`` and ``y`` are
  required, ``time``, ``z`` and ``confidence`` optional, extra columns ignored. Without ``z`` the
  data are 2D (``n_dims=2``, Z = 0).
* The file is plain CSV: the header is the first line, so ``pandas.read_csv`` and
  ``csv.DictReader`` read it with no options. The frame rate and the length unit travel in a
  sidecar JSON beside it, ``<file>.meta.json`` (``{"fps": 30.0, "length_unit": "m", ...}``),
  which the writer writes and the reader reads when it is there.
* Files written by earlier versions, with leading comment lines ``# fps: 30`` and
  ``# unit: m``, are still read; other leading ``#`` lines are ignored.
* The frame rate is the caller's ``fps``, else the sidecar's, else the ``# fps`` line, else
  derived from ``time`` (median seconds per frame between frames half the take apart) and
  snapped to a standard rate
  within 0.02 % (:func:`~mocapqa.io.keypoint_input.snap_fps`, recorded in ``assumptions``);
  without any of these the reader raises an error that asks for ``fps``.
* Keypoints keep the order of their first appearance. Frame numbers may start anywhere; a frame
  missing from the file is missing in the sequence. An empty cell or ``nan`` is missing;
  an empty ``confidence`` is 1.0 where the position exists.
* The unit is the caller's ``length_unit``, else the sidecar's, else the ``# unit`` line, else
  "unknown".
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.atomic import atomic_path
from mocapqa.io.guards import ReadLimits
from mocapqa.io.keypoint_input import (
    build_keypoint_sequence,
    decode_text,
    float_from_text,
    read_file_bytes,
    resolve_fps,
    resolve_length_unit,
    snap_fps,
)
from mocapqa.io.keypoint_rows import KeypointRow, dense_keypoints

__all__ = [
    "KEYPOINT_CSV_COLUMNS",
    "csv_sidecar",
    "csv_sidecar_path",
    "format_keypoint_csv",
    "is_csv_sidecar",
    "parse_keypoint_csv",
    "read_keypoint_csv",
    "write_keypoint_csv",
]

# Columns of the long CSV format; time, z and confidence are optional on read.
KEYPOINT_CSV_COLUMNS = ("frame", "time", "keypoint", "x", "y", "z", "confidence")
_REQUIRED = ("frame", "keypoint", "x", "y")


def _metadata(lines: list[str], path: str) -> tuple[dict[str, str], int]:
    meta: dict[str, str] = {}
    start = 0
    while start < len(lines) and (lines[start].startswith("#") or not lines[start].strip()):
        key, sep, value = lines[start].lstrip("#").partition(":")
        if sep:
            meta[key.strip().lower()] = value.strip()
        start += 1
    return meta, start


def _frame_number(text: str, path: str, line: int) -> int:
    value = float_from_text(text, path, line, "frame")
    if not (math.isfinite(value) and value == int(value) and abs(value) < 2**53):
        raise ParseError(f"Expected a whole frame number, got {text[:20]!r}", path, line, "frame")
    return int(value)


def csv_sidecar_path(path: str | Path) -> Path:
    """The metadata sidecar of a long keypoint CSV: ``walk.csv`` → ``walk.csv.meta.json``."""
    path = Path(path)
    return path.with_name(path.name + ".meta.json")


def is_csv_sidecar(name: str | Path) -> bool:
    """Whether a file name is a keypoint CSV's metadata sidecar (``*.csv.meta.json``, any
    case): read with its CSV, never a take of its own (batches and shoot imports skip it)."""
    return Path(name).name.lower().endswith(".csv.meta.json")


def _read_sidecar(path: str | Path) -> dict[str, Any] | None:
    sidecar = csv_sidecar_path(path)
    if not sidecar.is_file():
        return None
    try:
        data = json.loads(sidecar.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise ParseError(f"Expected a JSON metadata sidecar, got {e}", sidecar) from e
    if not isinstance(data, dict):
        raise ParseError(f"Expected a JSON object, got {type(data).__name__}", sidecar)
    fps = data.get("fps")
    if fps is not None and (isinstance(fps, bool) or not isinstance(fps, int | float)):
        raise ParseError(f"Expected a number, got {fps!r}", sidecar, field="fps")
    unit = data.get("length_unit")
    if unit is not None and not isinstance(unit, str):
        raise ParseError(f"Expected a unit name, got {unit!r}", sidecar, field="length_unit")
    return data


def _fps_from_times(frames: dict[int, float], path: str) -> float | None:
    known = sorted((f, t) for f, t in frames.items() if not math.isnan(t))
    if len(known) < 2:
        return None
    # Median slope between frames half the take apart: a time column rounded to 1 ms moves
    # one step of a 60 fps take by 6 %, but a half-take span by far less than the snapping
    # tolerance, and the median ignores an odd jump.
    table = np.array(known, dtype=np.float64)
    half = max(1, len(known) // 2)
    steps = table[half:] - table[:-half]
    seconds_per_frame = float(np.median(steps[:, 1] / steps[:, 0]))
    if not (math.isfinite(seconds_per_frame) and seconds_per_frame > 0):
        raise ParseError("Expected times increasing with frame numbers", path, field="time")
    return 1.0 / seconds_per_frame


def _fps_from_time_column(times: dict[int, float], path: str, notes: list[str]) -> float | None:
    estimate = _fps_from_times(times, path)
    return None if estimate is None else snap_fps(estimate, "the time column", notes)


def _table(lines: list[str], start: int, path: str) -> tuple[list[list[str]], dict[str, int]]:
    """The CSV cells below the metadata lines, and the header's column of each known name."""
    try:
        table = list(csv.reader(io.StringIO("\n".join(lines[start:]), newline="")))
    except csv.Error as e:
        raise ParseError(f"Expected CSV, got {e}", path) from e
    if not table:
        raise ParseError("Expected a header line, got an empty file", path, start + 1)
    header = [c.strip().lower() for c in table[0]]
    missing = [name for name in _REQUIRED if name not in header]
    if missing or len(set(header)) != len(header):
        raise ParseError(
            f"Expected unique columns including {','.join(_REQUIRED)}, got {header[:8]}",
            path,
            start + 1,
        )
    return table, {name: header.index(name) for name in KEYPOINT_CSV_COLUMNS if name in header}


@dataclass(slots=True)
class _Rows:
    """The data rows of a long keypoint CSV as read: names in order, times, row tuples."""

    names: dict[str, int] = field(default_factory=dict)
    times: dict[int, float] = field(default_factory=dict)
    rows: list[KeypointRow] = field(default_factory=list)


def _read_row(
    cells: list[str], col: dict[str, int], axes: list[str], path: str, line: int, read: _Rows
) -> None:
    """Check one data row and add it to ``read``."""
    frame = _frame_number(cells[col["frame"]], path, line)
    name = cells[col["keypoint"]].strip()
    if not name:
        raise ParseError("Expected a keypoint name, got an empty cell", path, line, "keypoint")
    xyz = [float_from_text(cells[col[a]], path, line, a) for a in axes]
    if len(axes) == 2:
        xyz.append(0.0 if not any(map(math.isnan, xyz)) else math.nan)
    conf = 1.0
    if "confidence" in col and cells[col["confidence"]].strip():
        conf = float_from_text(cells[col["confidence"]], path, line, "confidence")
        if not 0.0 <= conf <= 1.0:
            raise ParseError(f"Expected confidence in [0, 1], got {conf}", path, line, "confidence")
    if "time" in col:
        times = read.times
        t = float_from_text(cells[col["time"]], path, line, "time")
        if times.setdefault(frame, t) != t and not (math.isnan(t) and math.isnan(times[frame])):
            raise ParseError(f"Expected one time per frame {frame}", path, line, "time")
    read.rows.append((frame, read.names.setdefault(name, len(read.names)), xyz, conf, line))


def _data_rows(
    table: list[list[str]], col: dict[str, int], axes: list[str], path: str, start: int
) -> _Rows:
    """Every non-blank data row below the header (file line ``start + 1``)."""
    read = _Rows()
    width = len(table[0])
    for line, cells in enumerate(table[1:], start=start + 2):
        if not cells or not "".join(cells).strip():
            continue
        if len(cells) != width:
            raise ParseError(f"Expected {width} cells, got {len(cells)}", path, line)
        _read_row(cells, col, axes, path, line, read)
    return read


def _frame_rate(
    fps: float | None,
    meta: dict[str, str],
    side: dict[str, Any],
    times: dict[int, float],
    path: str,
    notes: list[str],
) -> float:
    """The caller's ``fps``, else the sidecar's, else the ``# fps`` line, else the times'."""
    file_fps = float_from_text(meta["fps"], path, None, "fps") if "fps" in meta else None
    if side.get("fps") is not None:
        file_fps = float(side["fps"])
    if fps is None and file_fps is None:
        file_fps = _fps_from_time_column(times, path, notes)
    return resolve_fps(fps, file_fps, None, path, "CSV", notes)


def parse_keypoint_csv(
    data: bytes | str,
    path: str | Path = "<keypoints.csv>",
    fps: float | None = None,
    length_unit: str | None = None,
    sidecar: dict[str, Any] | None = None,
    limits: ReadLimits | None = None,
) -> KeypointSequence:
    """Parse the long keypoint CSV into a :class:`~mocapqa.core.keypoints.KeypointSequence`.

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.
    fps : float, optional
        Frames per second; required when the file has neither ``time`` nor ``# fps``.
    length_unit : str, optional
        Unit of x, y, z when the file has no ``# unit`` line.
    sidecar : dict, optional
        The file's metadata sidecar (``fps``, ``length_unit``), read by
        :func:`read_keypoint_csv`.
    limits : ReadLimits, optional
        Refuse a take spanning more frames × keypoints than ``limits.max_frame_points``
        before its arrays are made (the frame numbers and names can claim far more than the
        rows hold).

    Returns
    -------
    KeypointSequence
        Positions ``(F, K, 3)``; F spans the first to the last frame number.

    Raises
    ------
    ParseError
        On a bad header, row, cell, duplicate (frame, keypoint), or a missing frame rate,
        naming the file, the line and the column.
    TooLargeError
        Beyond ``limits``.
    """
    path = str(path)
    lines = decode_text(data, path).splitlines()
    meta, start = _metadata(lines, path)
    table, col = _table(lines, start, path)
    axes = [a for a in "xyz" if a in col]
    read = _data_rows(table, col, axes, path, start)
    if not read.rows:
        raise ParseError("Expected at least one data row, got none", path, len(lines))
    dense = dense_keypoints(
        read.rows,
        len(read.names),
        path,
        limits,
        lambda frame, point: "Expected one row per frame and keypoint, got a repeat",
    )
    notes: list[str] = []
    side = sidecar or {}
    rate = _frame_rate(fps, meta, side, read.times, path, notes)
    file_unit = side.get("length_unit") or meta.get("unit")
    unit = resolve_length_unit(length_unit or file_unit, "unknown", path, notes)
    numbers = dense.first + np.arange(dense.n_frames)
    times = read.times
    column = np.array([times.get(int(f), math.nan) for f in numbers]) if times else None
    return build_keypoint_sequence(
        path, tuple(read.names), dense.positions, dense.confidence, rate,
        length_unit=unit, n_dims=len(axes), source_format="csv", assumptions=notes,
        frame_numbers=numbers, times=column,
    )  # fmt: skip


def read_keypoint_csv(
    path: str | Path,
    fps: float | None = None,
    length_unit: str | None = None,
    limits: ReadLimits | None = None,
) -> KeypointSequence:
    """Read a long keypoint CSV file and its sidecar, if any. See :func:`parse_keypoint_csv`."""
    data = read_file_bytes(path)
    return parse_keypoint_csv(data, path, fps, length_unit, _read_sidecar(path), limits)


def _cell(value: float) -> str:
    return "" if math.isnan(value) else repr(float(value))


def format_keypoint_csv(seq: KeypointSequence) -> str:
    """Format a sequence as the long keypoint CSV: the header, then one row per frame × keypoint.

    Parameters
    ----------
    seq : KeypointSequence
        The data; 2D sequences are written without ``z``.

    Returns
    -------
    str
        The file content (LF line endings); missing values are empty cells. Frame numbers and
        times are the source's when it had them, else ``0..F-1`` and ``frame / fps``.
    """
    axes = 2 if seq.n_dims == 2 else 3
    columns = [c for c in KEYPOINT_CSV_COLUMNS if c != "z" or axes == 3]
    out = [",".join(columns)]
    numbers = range(seq.n_frames) if seq.frame_numbers is None else seq.frame_numbers.tolist()
    for frame, number in enumerate(numbers):
        time = _cell(float(seq.times[frame])) if seq.times is not None else repr(frame / seq.fps)
        for k, name in enumerate(seq.names):
            coords = ",".join(_cell(v) for v in seq.positions[frame, k, :axes])
            conf = repr(float(seq.confidence[frame, k]))
            out.append(f"{number},{time},{_quoted(name)},{coords},{conf}")
    return "\n".join(out) + "\n"


def _quoted(name: str) -> str:
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="").writerow([name])
    return buffer.getvalue()


def csv_sidecar(seq: KeypointSequence) -> dict[str, Any]:
    """The metadata written beside a long keypoint CSV (see :func:`csv_sidecar_path`)."""
    return {
        "format": "mocapqa long keypoint CSV",
        "columns": [c for c in KEYPOINT_CSV_COLUMNS if c != "z" or seq.n_dims != 2],
        "fps": seq.fps,
        "length_unit": seq.length_unit,
        "n_frames": seq.n_frames,
        "keypoints": list(seq.names),
        "assumptions": list(seq.assumptions),
    }


def write_keypoint_csv(path: str | Path, seq: KeypointSequence) -> None:
    """Write a sequence as a long keypoint CSV file and its ``.meta.json`` sidecar.

    Both are written to temporary files first and renamed into place only when both were
    written (:mod:`mocapqa.io.atomic`); a failure leaves the old pair as it was.

    Parameters
    ----------
    path, seq : str or Path, KeypointSequence
        The destination file, and the data.
    """
    path = Path(path)
    sidecar = csv_sidecar_path(path)
    with atomic_path(path) as table, atomic_path(sidecar) as meta:
        table.write_text(format_keypoint_csv(seq), encoding="utf-8", newline="\n")
        meta.write_text(json.dumps(csv_sidecar(seq), indent=1), encoding="utf-8")
