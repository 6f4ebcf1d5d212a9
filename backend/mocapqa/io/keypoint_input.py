"""Shared input steps of the keypoint readers: reading text, parsing numbers, building sequences.

Conventions
-----------
* Every problem becomes :class:`~mocapqa.errors.ParseError` naming the file and, where known,
  the 1-based line or the field; a :class:`~mocapqa.errors.ShapeError` raised while building
  the :class:`~mocapqa.core.keypoints.KeypointSequence` is wrapped the same way.
* Number text follows Python's ``float``: ``nan`` means missing; infinity is rejected.
* Coordinates lie within ±:data:`~mocapqa.core.bounds.MAX_MAGNITUDE` (1e9), the bound the BVH
  reader keeps: every reader builds its sequence with :func:`build_keypoint_sequence`, which
  refuses a larger one (:func:`check_coordinates`) before a filter squares it into infinity.
* The frame rate is resolved in one place: a caller's ``fps`` wins, then the file's, then a
  reader-specific default that is recorded in ``KeypointSequence.assumptions``, or an error
  when the format has no default.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.core.bounds import MAX_MAGNITUDE
from mocapqa.core.keypoints import LENGTH_UNITS, KeypointSequence
from mocapqa.errors import ParseError, ShapeError
from mocapqa.io.guards import json_nesting

__all__ = [
    "FPS_SNAP_TOLERANCE",
    "JSON_PARSE_DEPTH",
    "MAX_FILE_BYTES",
    "STANDARD_FPS",
    "build_keypoint_sequence",
    "check_coordinates",
    "decode_text",
    "float_from_text",
    "parse_json",
    "read_file_bytes",
    "resolve_fps",
    "resolve_length_unit",
    "snap_fps",
]

# Largest keypoint file read into memory, bytes.
MAX_FILE_BYTES = 2**31


def read_file_bytes(path: str | Path) -> bytes:
    """Read a whole file, turning OS errors into ParseError.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    bytes
        The content.

    Raises
    ------
    ParseError
        When the file cannot be read.
    """
    try:
        return Path(path).read_bytes()
    except OSError as e:
        raise ParseError(f"Expected a readable file, got {e.strerror or e}", path) from e


def decode_text(data: bytes | str, path: str | Path) -> str:
    """Decode file content as UTF-8 (a BOM is dropped); binary content raises ParseError.

    Parameters
    ----------
    data : bytes or str
        Raw content, or already decoded text.
    path : str or Path
        The file name used in messages.

    Returns
    -------
    str
        The text.

    Raises
    ------
    ParseError
        On NUL bytes or bytes that are not UTF-8, with the line where they occur.
    """
    if isinstance(data, str):
        text = data.removeprefix("\ufeff")  # text read elsewhere may still start with a BOM
    else:
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError as e:
            line = data[: e.start].count(b"\n") + 1
            raise ParseError("Expected UTF-8 text, got undecodable bytes", path, line) from e
    if "\x00" in text:
        line = text[: text.index("\x00")].count("\n") + 1
        raise ParseError("Expected a text file, got binary data (NUL bytes)", path, line)
    return text


JSON_PARSE_DEPTH = 512
"""Deepest nesting of arrays and objects the JSON readers parse, whatever the reading limits
(the server's ``max_json_depth``, 64, refuses deeper files first): Python's parser recurses
once per level and fails near its recursion limit of 1,000 calls."""


def parse_json(data: bytes | str, path: str | Path) -> Any:
    """Parse a JSON document of a keypoint format (see :func:`decode_text` for the text).

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.

    Returns
    -------
    object
        The document.

    Raises
    ------
    ParseError
        On text that is not UTF-8, invalid JSON (with its line), or a document nested deeper
        than :data:`JSON_PARSE_DEPTH`.
    """
    text = decode_text(data, path)
    deepest, _ = json_nesting(data if isinstance(data, bytes) else text.encode("utf-8"))
    too_deep = f"Expected JSON nested at most {JSON_PARSE_DEPTH} deep, got deeper"
    if deepest > JSON_PARSE_DEPTH:
        raise ParseError(too_deep, path)
    try:
        return json.loads(text)
    except json.JSONDecodeError as e:
        raise ParseError(f"Expected valid JSON, got {e.msg}", path, e.lineno) from e
    except RecursionError as e:  # a backstop: deep in a caller's stack, fewer levels parse
        raise ParseError(too_deep, path) from e


def float_from_text(
    text: str, path: str | Path, line: int | None = None, field: str | None = None
) -> float:
    """Parse one number cell; an empty cell or ``nan`` gives NaN.

    Parameters
    ----------
    text : str
        The cell, surrounding spaces allowed.
    path : str or Path
        The file name used in messages.
    line : int, optional
        1-based line number, for messages.
    field : str, optional
        Column or field name, for messages.

    Returns
    -------
    float
        The value, NaN for a missing cell.

    Raises
    ------
    ParseError
        On text that is not a number, or on infinity.
    """
    cell = text.strip()
    if not cell:
        return math.nan
    try:
        value = float(cell)
    except ValueError as e:
        raise ParseError(f"Expected a number, got {cell[:40]!r}", path, line, field) from e
    if math.isinf(value):
        raise ParseError(f"Expected a finite number or NaN, got {cell[:40]!r}", path, line, field)
    return value


def resolve_fps(
    caller_fps: float | None,
    file_fps: float | None,
    default_fps: float | None,
    path: str | Path,
    format_name: str,
    assumptions: list[str],
) -> float:
    """Choose the frame rate: the caller's, else the file's, else a recorded default.

    Parameters
    ----------
    caller_fps : float or None
        Frames per second passed by the caller.
    file_fps : float or None
        Frames per second stored in the file.
    default_fps : float or None
        The reader's default when neither is known; None makes the frame rate required.
    path : str or Path
        The file name used in messages.
    format_name : str
        The format's name, used in messages and assumptions.
    assumptions : list of str
        Appended to when the default is used.

    Returns
    -------
    float
        Frames per second (> 0).

    Raises
    ------
    ParseError
        When no frame rate is known and there is no default, or a value is not positive.
    """
    fps = caller_fps if caller_fps is not None else file_fps
    if fps is None:
        if default_fps is None:
            raise ParseError(
                f"Expected a frame rate: {format_name} input without a time column or fps "
                "field needs the fps argument (the upload's fps field, or --fps 30 on the "
                "command line)",
                path,
                field="fps",
            )
        fps = default_fps
        assumptions.append(f"fps {default_fps:g} assumed: {format_name} stores no frame rate")
    if not (math.isfinite(fps) and fps > 0):
        raise ParseError(f"Expected a finite fps > 0, got {fps}", path, field="fps")
    return float(fps)


STANDARD_FPS: tuple[float, ...] = (
    24000 / 1001, 24.0, 25.0, 30000 / 1001, 30.0, 48.0, 50.0, 60000 / 1001, 60.0, 72.0, 90.0,
    96.0, 100.0, 120000 / 1001, 120.0, 144.0, 150.0, 180.0, 200.0, 240.0, 250.0, 300.0, 360.0,
    400.0, 480.0, 500.0, 960.0, 1000.0,
)  # fmt: skip
"""Camera and mocap frame rates an estimate is snapped to (NTSC rates as 24000/1001 etc.)."""
FPS_SNAP_TOLERANCE = 2e-4
"""Largest relative distance (0.02 %) from a standard rate that is snapped to it; 29.97 and 30
differ by 0.1 %, so they stay apart."""


def snap_fps(estimate: float, source: str, assumptions: list[str]) -> float:
    """Snap a frame rate estimated from times to the nearest standard rate, and say so.

    Parameters
    ----------
    estimate : float
        Frames per second estimated from a time column (> 0).
    source : str
        What it was estimated from, for the note (``"the time column"``).
    assumptions : list of str
        Appended to with what was done.

    Returns
    -------
    float
        The standard rate within :data:`FPS_SNAP_TOLERANCE`, else ``estimate``.

    Examples
    --------
    >>> notes = []
    >>> snap_fps(30.0003, "the time column", notes)
    30.0
    >>> notes[0]
    'fps 30.0003 estimated from the time column, snapped to the standard 30 (within 0.02 %)'
    """
    nearest = min(STANDARD_FPS, key=lambda rate: abs(estimate / rate - 1.0))
    if abs(estimate / nearest - 1.0) <= FPS_SNAP_TOLERANCE:
        assumptions.append(
            f"fps {estimate:.6g} estimated from {source}, snapped to the standard "
            f"{nearest:.6g} (within {100 * FPS_SNAP_TOLERANCE:g} %)"
        )
        return nearest
    assumptions.append(
        f"fps {estimate:.6g} estimated from {source} (no standard rate within "
        f"{100 * FPS_SNAP_TOLERANCE:g} %)"
    )
    return estimate


def resolve_length_unit(
    caller_unit: str | None, default_unit: str, path: str | Path, assumptions: list[str]
) -> str:
    """Choose the length unit of a format that does not store one.

    Parameters
    ----------
    caller_unit : str or None
        The caller's ``length_unit``; wins when given.
    default_unit : str
        The unit the format implies ("unknown" when it implies none).
    path : str or Path
        The file name used in messages.
    assumptions : list of str
        Appended to when a unit other than "unknown" is implied rather than given.

    Returns
    -------
    str
        One of :data:`~mocapqa.core.keypoints.LENGTH_UNITS`.

    Raises
    ------
    ParseError
        When the caller's unit is not a known one.
    """
    if caller_unit is not None:
        if caller_unit not in LENGTH_UNITS:
            raise ParseError(
                f"Expected length_unit in {LENGTH_UNITS}, got {caller_unit!r}", path, field="unit"
            )
        return caller_unit
    if default_unit != "unknown":
        assumptions.append(f"length unit {default_unit!r} implied by the format, not stored")
    return default_unit


def check_coordinates(
    positions: FloatArray,
    path: str | Path,
    names: tuple[str, ...] | None = None,
    frame_numbers: IntArray | None = None,
) -> None:
    """Refuse coordinates beyond ±:data:`~mocapqa.core.bounds.MAX_MAGNITUDE` (NaN is missing).

    Parameters
    ----------
    positions : ndarray, shape (F, K, 3)
        Coordinates.
    path : str or Path
        The file named in the message.
    names : tuple of str, optional
        Keypoint names, to name the first coordinate out of range.
    frame_numbers : ndarray of int, shape (F,), optional
        The source's frame numbers, to name its frame (else the 0-based frame index).

    Raises
    ------
    ParseError
        Naming the file, the field ``positions``, the value, its frame and keypoint.
    """
    values = np.asarray(positions, dtype=np.float64)
    if values.size == 0:
        return
    # Two reductions without a temporary |values| array (the take may be large).
    if np.nanmax(values, initial=-np.inf) <= MAX_MAGNITUDE and (
        np.nanmin(values, initial=np.inf) >= -MAX_MAGNITUDE
    ):
        return
    where = tuple(int(i) for i in np.argwhere(np.abs(values) > MAX_MAGNITUDE)[0])
    frame = where[0]
    if frame_numbers is not None and len(frame_numbers) == len(values):
        frame = int(frame_numbers[frame])
    point = f"keypoint {where[1]}"
    if names is not None and len(names) == values.shape[1]:
        point = f"keypoint {names[where[1]]!r}"
    raise ParseError(
        f"Expected coordinates within ±{int(MAX_MAGNITUDE):,}, got {values[where]:g} "
        f"(frame {frame}, {point})",
        path,
        field="positions",
    )


def build_keypoint_sequence(
    path: str | Path,
    names: tuple[str, ...],
    positions: FloatArray,
    confidence: FloatArray,
    fps: float,
    *,
    length_unit: str,
    n_dims: int,
    source_format: str,
    assumptions: list[str] | tuple[str, ...] = (),
    frame_numbers: IntArray | None = None,
    times: FloatArray | None = None,
    start_frame: int | None = None,
) -> KeypointSequence:
    """Build a KeypointSequence, turning its validation errors into ParseError for ``path``.

    Parameters
    ----------
    path : str or Path
        The file the data came from.
    names : tuple of str
        Keypoint names, K of them.
    positions : ndarray, shape (F, K, 3)
        Coordinates in ``length_unit``, NaN where missing.
    confidence : ndarray, shape (F, K)
        Confidence in [0, 1].
    fps : float
        Frames per second.
    length_unit, source_format : str
        As in :class:`~mocapqa.core.keypoints.KeypointSequence`.
    n_dims : int
        2 or 3.
    assumptions : sequence of str
        Recorded assumptions.
    frame_numbers, times, start_frame : optional
        The source's frame numbers, time column and first-frame field (see
        :class:`~mocapqa.core.keypoints.KeypointSequence`).

    Returns
    -------
    KeypointSequence
        The sequence, its coordinates checked.

    Raises
    ------
    ParseError
        When the data do not make a valid sequence (duplicate names, confidence outside [0, 1]),
        or a coordinate lies beyond ±1e9 (:func:`check_coordinates`).
    """
    check_coordinates(positions, path, tuple(names), frame_numbers)
    try:
        return KeypointSequence(
            names=tuple(names),
            positions=np.asarray(positions, dtype=np.float64),
            confidence=np.asarray(confidence, dtype=np.float64),
            fps=fps,
            length_unit=length_unit,
            n_dims=n_dims,
            source_format=source_format,
            assumptions=tuple(assumptions),
            frame_numbers=frame_numbers,
            times=times,
            start_frame=start_frame,
        )
    except ShapeError as e:
        raise ParseError(str(e), path) from e
