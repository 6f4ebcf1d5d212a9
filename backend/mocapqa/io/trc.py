"""OpenSim TRC (track row column) marker files: reader and writer.

Conventions
-----------
* Layout: line 1 ``PathFileType 4 (X/Y/Z) name``; line 2 header keys; line 3 their values
  (``DataRate``, ``NumFrames``, ``NumMarkers``, ``Units``, ...); line 4 ``Frame# Time`` and
  the marker names; line 5 the ``X1 Y1 Z1 ...`` labels; then data rows ``frame time x y z ...``.
* Tolerated variants (all seen in Pose2Sim output): extra tabs after the marker names, no blank
  line before the data, ``PathFileType  4`` with spaces, ``DataRate`` as ``60`` or ``60.0``,
  time written with any precision, frame numbers from 1, CRLF line endings.
* Cells are tab-separated (a file without tabs is split on spaces). An empty cell or ``nan``
  is a missing value (NaN); infinity and text are errors. Each row must hold ``2 + 3 * M``
  cells; extra empty cells at the end of a row are ignored.
* The frame rate is ``DataRate``; the unit is ``Units`` (``m``, ``mm``, ``cm``, ``in``, also
  spelled out), recorded as is and never rescaled. Confidence is 1.0 where a value exists.
* The reader keeps the ``Frame#`` and ``Time`` columns (when frame numbers are whole and
  increasing) and ``OrigDataStartFrame``. The writer numbers frames from 1, the OpenSim
  convention, whatever the source's first number (an OpenPose folder's files count from 0):
  the source's numbers are shifted so the first is 1, their gaps kept. It writes the source's
  times as they were, and ``OrigDataStartFrame`` as the source's own field, else its first
  frame number (0 for an OpenPose folder), else 1. A sequence without numbers or times is
  written with frames from 1 at ``index / DataRate`` seconds.
* The writer prints every number with Python's shortest round-trip repr, so a written file
  reads back exactly, and writes every cell of every row: a missing value is ``NaN`` (an
  empty trailing cell makes OpenSim refuse the file for a short row). Confidence is not
  stored.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from mocapqa.core.keypoints import LENGTH_UNITS, KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.atomic import write_text
from mocapqa.io.keypoint_input import (
    build_keypoint_sequence,
    decode_text,
    float_from_text,
    read_file_bytes,
)

__all__ = ["TRC_UNIT_ALIASES", "format_trc", "parse_trc", "read_trc", "write_trc"]

# Spellings of TRC "Units" values mapped to our length units.
TRC_UNIT_ALIASES: dict[str, str] = {
    "m": "m",
    "meter": "m",
    "meters": "m",
    "metre": "m",
    "metres": "m",
    "mm": "mm",
    "millimeter": "mm",
    "millimeters": "mm",
    "cm": "cm",
    "centimeter": "cm",
    "centimeters": "cm",
    "in": "in",
    "inch": "in",
    "inches": "in",
    **{unit: unit for unit in LENGTH_UNITS},
}

_LABEL = re.compile(r"^[XYZ]\d+$", re.IGNORECASE)


def _cells(line: str) -> list[str]:
    return line.split("\t") if "\t" in line else line.split()


def _header_values(lines: list[str], path: str) -> dict[str, str]:
    keys = [k.strip() for k in _cells(lines[1])]
    values = [v.strip() for v in _cells(lines[2])]
    if "DataRate" not in keys:
        raise ParseError(f"Expected header keys with DataRate, got {lines[1][:60]!r}", path, 2)
    return {k: (values[i] if i < len(values) else "") for i, k in enumerate(keys) if k}


def _unit(header: dict[str, str], path: str) -> str:
    text = header.get("Units", "").strip()
    if not text:
        return "unknown"
    unit = TRC_UNIT_ALIASES.get(text.lower())
    if unit is None:
        raise ParseError(
            f"Expected Units among m, mm, cm, in, got {text[:20]!r}", path, 3, field="Units"
        )
    return unit


def _count(header: dict[str, str], key: str, path: str) -> int | None:
    text = header.get(key, "").strip()
    if not text:
        return None
    value = float_from_text(text, path, 3, key)
    if not (math.isfinite(value) and value >= 0 and value == int(value)):
        raise ParseError(f"Expected a whole number for {key}, got {text[:20]!r}", path, 3, key)
    return int(value)


def _marker_names(lines: list[str], path: str) -> tuple[str, ...]:
    cells = [c.strip() for c in _cells(lines[3])]
    if len(cells) < 2 or cells[0].lower() != "frame#":
        raise ParseError(f"Expected 'Frame#\\tTime\\t<markers>', got {lines[3][:60]!r}", path, 4)
    names = tuple(c for c in cells[2:] if c)
    if not names:
        raise ParseError("Expected at least one marker name, got none", path, 4)
    if len(set(names)) != len(names):
        raise ParseError("Expected unique marker names, got duplicates", path, 4)
    return names


def parse_trc(data: bytes | str, path: str | Path = "<trc>") -> KeypointSequence:
    """Parse TRC text into a :class:`~mocapqa.core.keypoints.KeypointSequence`.

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.

    Returns
    -------
    KeypointSequence
        Positions ``(F, M, 3)`` in the file's unit, confidence 1.0 where present, fps from
        ``DataRate``, ``source_format="trc"``.

    Raises
    ------
    ParseError
        On any malformed header or row, naming the file and the 1-based line.
    """
    path = str(path)
    lines = decode_text(data, path).splitlines()
    if not lines or not lines[0].lstrip().startswith("PathFileType"):
        first = lines[0][:40] if lines else ""
        raise ParseError(f"Expected a TRC file starting 'PathFileType', got {first!r}", path, 1)
    if len(lines) < 4:
        raise ParseError(
            f"Expected a TRC header of 3 lines and a marker row, got {len(lines)} line(s)",
            path,
            len(lines),
        )
    header = _header_values(lines, path)
    fps = float_from_text(header["DataRate"], path, 3, "DataRate")
    if not (math.isfinite(fps) and fps > 0):
        raise ParseError(f"Expected DataRate > 0, got {header['DataRate'][:20]!r}", path, 3)
    unit = _unit(header, path)
    names = _marker_names(lines, path)
    n_markers = _count(header, "NumMarkers", path)
    if n_markers is not None and n_markers != len(names):
        raise ParseError(
            f"Expected {n_markers} marker names (NumMarkers), got {len(names)}", path, 4
        )
    start = 4
    if len(lines) > 4 and any(_LABEL.match(c.strip()) for c in _cells(lines[4])):
        start = 5
    width = 2 + 3 * len(names)
    rows: list[list[float]] = []
    frame_cells: list[float] = []
    time_cells: list[float] = []
    for number, line in enumerate(lines[start:], start=start + 1):
        if not line.strip():
            continue
        cells = _cells(line)
        while len(cells) > width and not cells[-1].strip():
            cells.pop()
        if len(cells) != width:
            raise ParseError(
                f"Expected {width} cells (Frame#, Time and 3 per marker), got {len(cells)}",
                path,
                number,
            )
        frame_cells.append(float_from_text(cells[0], path, number, "Frame#"))
        time_cells.append(float_from_text(cells[1], path, number, "Time"))
        rows.append([float_from_text(c, path, number) for c in cells[2:]])
    n_frames = _count(header, "NumFrames", path)
    if n_frames is not None and n_frames != len(rows):
        raise ParseError(
            f"Expected {n_frames} data rows (NumFrames), got {len(rows)}", path, len(lines)
        )
    positions = np.array(rows, dtype=np.float64).reshape(len(rows), len(names), 3)
    confidence = np.ones(positions.shape[:2])
    frames = np.array(frame_cells)
    whole = bool(np.all(np.isfinite(frames)) and np.all(frames == np.round(frames)))
    increasing = whole and bool(np.all(np.diff(frames) > 0))
    return build_keypoint_sequence(
        path, names, positions, confidence, fps, length_unit=unit, n_dims=3, source_format="trc",
        frame_numbers=frames.astype(np.intp) if increasing else None,
        times=np.array(time_cells), start_frame=_count(header, "OrigDataStartFrame", path),
    )  # fmt: skip


def read_trc(path: str | Path) -> KeypointSequence:
    """Read a TRC file. See :func:`parse_trc` for the result and errors."""
    return parse_trc(read_file_bytes(path), path)


def _number(value: float) -> str:
    return "NaN" if math.isnan(value) else repr(float(value))


def format_trc(seq: KeypointSequence, file_name: str = "keypoints.trc") -> str:
    """Format a sequence as TRC text (tab-separated, LF line endings).

    Parameters
    ----------
    seq : KeypointSequence
        The data; its ``length_unit`` goes into ``Units`` and its fps into ``DataRate``.
    file_name : str
        Name written on the ``PathFileType`` line.

    Returns
    -------
    str
        The file content; numbers use the shortest repr that reads back exactly.
    """
    n_frames, n_markers = seq.n_frames, seq.n_keypoints
    fps = repr(seq.fps)
    source = seq.frame_numbers if seq.frame_numbers is not None else np.arange(n_frames)
    # OpenSim numbers frames from 1: the source's numbers are shifted there, gaps kept.
    numbers = (source - (source[0] if n_frames else 0) + 1).tolist()
    times = seq.times if seq.times is not None else np.arange(n_frames) / seq.fps
    first = seq.start_frame
    if first is None:
        first = int(seq.frame_numbers[0]) if seq.frame_numbers is not None and n_frames else 1
    out = [
        f"PathFileType\t4\t(X/Y/Z)\t{file_name}",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
        "OrigDataStartFrame\tOrigNumFrames",
        f"{fps}\t{fps}\t{n_frames}\t{n_markers}\t{seq.length_unit}\t{fps}\t{first}\t{n_frames}",
        "Frame#\tTime\t" + "\t".join(f"{name}\t\t" for name in seq.names),
        "\t\t" + "\t".join(f"X{i}\tY{i}\tZ{i}" for i in range(1, n_markers + 1)),
        "",
    ]
    flat = seq.positions.reshape(n_frames, 3 * n_markers)
    for frame, number in enumerate(numbers):
        values = "\t".join(_number(v) for v in flat[frame])
        out.append(f"{number}\t{_number(float(times[frame]))}\t{values}")
    return "\n".join(out) + "\n"


def write_trc(path: str | Path, seq: KeypointSequence) -> None:
    """Write a sequence as a TRC file, whole or not at all (:mod:`mocapqa.io.atomic`).

    Parameters
    ----------
    path : str or Path
        Destination file.
    seq : KeypointSequence
        The data. Confidence is not stored; 2D data are written with their zero Z.
    """
    path = Path(path)
    write_text(path, format_trc(seq, path.name))
