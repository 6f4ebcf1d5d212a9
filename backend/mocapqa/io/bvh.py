"""BVH reader (the writer is :mod:`mocapqa.io.bvh_write`).

Conventions
-----------
* Reads any hierarchy (:mod:`mocapqa.io.bvh_hierarchy`: keywords in any case, names with
  spaces), 0-, 3- or 6-channel joints (position channels on non-root joints are kept and used
  by forward kinematics), any rotation order per joint, End Sites, tabs or spaces,
  CRLF/LF/CR/mixed line endings, UTF-8 or UTF-16 with a byte order mark, trailing spaces,
  exponents, ``-0`` and ``.0083333``.
* Refuses what no take holds: a Frame Time outside :data:`MIN_FRAME_TIME_S` to
  :data:`MAX_FRAME_TIME_S`, values beyond :data:`~mocapqa.core.bounds.MAX_MAGNITUDE`, more
  than :data:`~mocapqa.io.bvh_hierarchy.MAX_JOINTS` joints.
* Rotation channels are intrinsic in channel order (see :mod:`mocapqa.kinematics.euler`) and are
  converted to local quaternions ``(F, J, 4)``; the angles read are kept as the motion's
  ``euler_hint_deg`` so that writing an unchanged take reproduces its numbers.
* Root translation semantics: BVH says position channels replace the OFFSET. Character Creator
  exports whose root keeps a large rest OFFSET write small deltas instead; ``"auto"`` detects
  this (channels much nearer zero than the OFFSET) and records ``root_translation="add"``.
* Every problem raises :class:`~mocapqa.errors.ParseError` (alias :data:`BvhParseError`) with
  the file, the 1-based line and what was expected.
"""

from __future__ import annotations

import codecs
import math
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Literal, TypeVar

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.bounds import MAX_FPS, MIN_FPS
from mocapqa.core.motion import POSITION_CHANNELS, Motion, Skeleton
from mocapqa.errors import ParseError
from mocapqa.io.bvh_frames import frames_by_arrow, frames_by_line, quoted
from mocapqa.io.bvh_hierarchy import Hierarchy, parse_hierarchy
from mocapqa.kinematics.euler import quats_from_euler

__all__ = [
    "AUTO_ARROW_BYTES",
    "MAX_FRAME_TIME_S",
    "MIN_FRAME_TIME_S",
    "BvhParseError",
    "NumberReader",
    "parse_bvh",
    "read_bvh",
]

BvhParseError = ParseError
"""Alias of :class:`~mocapqa.errors.ParseError`, the error every malformed BVH raises."""
NumberReader = Literal["arrow", "python", "auto"]
"""How the frame block's numbers are read (see :func:`parse_bvh`)."""
MIN_FRAME_TIME_S = 1 / MAX_FPS
"""Shortest Frame Time accepted, 1e-5 s (:data:`~mocapqa.core.bounds.MAX_FPS`, 100,000 fps):
ten times the fastest motion-capture cameras."""
MAX_FRAME_TIME_S = 1 / MIN_FPS
"""Longest Frame Time accepted, 10 s (:data:`~mocapqa.core.bounds.MIN_FPS`, 0.1 fps); a larger
one is most often a frame rate."""
AUTO_ARROW_BYTES = 1_000_000
"""Frame blocks from this size are read by Arrow under ``number_reader="auto"``.

Below it, in a process that has not loaded pyarrow yet, importing it (~0.05 s) costs more than
the line-by-line reader (~0.07 s per MB) takes for the whole block.
"""


def _decode(data: bytes, path: str) -> str:
    if data[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE):
        # Windows tools (PowerShell's redirection, Notepad's "Unicode") save UTF-16.
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError as e:
            line = data[: e.start].decode("utf-16", errors="replace").count("\n") + 1
            raise ParseError(
                "Expected UTF-16 text after its byte order mark, got undecodable bytes", path, line
            ) from e
    if b"\x00" in data[:65536]:
        raise ParseError("Expected a text file, got binary data (NUL bytes)", path, 1)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise ParseError("Expected UTF-8 or ASCII text, got undecodable bytes", path, line) from e
    return text


_MOTION = re.compile(r"^[^\S\n]*MOTION[^\S\n]*$", re.MULTILINE | re.IGNORECASE)
_FRAMES = re.compile(r"\s*FRAMES\s*:(.*)", re.IGNORECASE | re.DOTALL)
_FRAME_TIME = re.compile(r"\s*FRAME\s+TIME\s*:(.*)", re.IGNORECASE | re.DOTALL)


class _LineCursor:
    """Walks LF-separated lines of ``text`` from ``position`` (the end of line ``number``)."""

    def __init__(self, text: str, position: int, number: int) -> None:
        self.text = text
        self.number = number  # 0-based index of the line last returned
        end = text.find("\n", position)
        self.position = len(text) if end < 0 else end + 1

    def next_line(self) -> str | None:
        if self.position >= len(self.text):
            return None
        end = self.text.find("\n", self.position)
        end = len(self.text) if end < 0 else end
        line = self.text[self.position : end]
        self.position = end + 1
        self.number += 1
        return line

    def next_nonblank(self) -> str | None:
        line = self.next_line()
        while line is not None and not line.strip():
            line = self.next_line()
        return line


def _header_value(line: str, pattern: re.Pattern[str], key: str, path: str, number: int) -> str:
    match = pattern.match(line)
    if match is None:
        raise ParseError(f"Expected {key!r}, got {quoted(line.strip())}", path, number)
    return match.group(1).strip()


def _check_frame_time(frame_time: float, text: str, path: str, line: int) -> None:
    if not (math.isfinite(frame_time) and frame_time > 0):
        raise ParseError(f"Expected a frame time > 0 s, got {quoted(text)}", path, line)
    if not MIN_FRAME_TIME_S <= frame_time <= MAX_FRAME_TIME_S:
        hint = ""
        if frame_time > MAX_FRAME_TIME_S and frame_time.is_integer():
            hint = (
                " (a frame rate? Frame Time is seconds per frame, "
                f"{1 / frame_time:.7g} for {frame_time:g} fps)"
            )
        raise ParseError(
            f"Expected a frame time from {MIN_FRAME_TIME_S:g} to {MAX_FRAME_TIME_S:g} s, "
            f"got {quoted(text)}{hint}",
            path,
            line,
        )


def parse_bvh(
    data: bytes | str,
    path: str | Path = "<bvh>",
    root_translation: Literal["auto", "replace", "add"] = "auto",
    length_unit: str = "unknown",
    number_reader: NumberReader = "arrow",
) -> Motion:
    """Parse BVH text into a :class:`~mocapqa.core.motion.Motion`.

    Parameters
    ----------
    data : bytes or str
        The file's content.
    path : str or Path
        Name used in error messages.
    root_translation : {"auto", "replace", "add"}
        How root position channels combine with the root OFFSET (see module notes).
    length_unit : str
        Unit of lengths in the file, when the caller knows it.
    number_reader : {"arrow", "python", "auto"}
        How the frame block's numbers are read: "arrow" with pyarrow's CSV reader (~8×
        faster), "python" line by line with ``float``; "auto" for a one-off read in a fresh
        process (the CLI): Arrow when pyarrow is loaded already or the block is at least
        :data:`AUTO_ARROW_BYTES`, else line by line. The numbers are the same; malformed
        input, or a machine without pyarrow, always ends on the line-by-line path, which
        reports the line.

    Returns
    -------
    Motion

    Raises
    ------
    ParseError
        On any malformed input, with the file and line.
    """
    path = str(path)
    text = _decode(data, path) if isinstance(data, bytes) else data
    if "\r" in text and "\n" not in text:
        text = text.replace("\r", "\n")  # classic Mac line endings
    # Lines are counted by LF everywhere (CR is whitespace), so error line numbers agree with
    # editors for LF, CRLF and mixed files.
    hierarchy, cursor = _sections(text, path)
    n_frames, frame_time = _motion_header(cursor, path)
    n_channels = sum(len(c) for c in hierarchy.channels)
    block = text[cursor.position :]
    if number_reader == "auto":
        big = len(block) >= AUTO_ARROW_BYTES
        number_reader = "arrow" if big or "pyarrow.csv" in sys.modules else "python"
    values = None
    if number_reader == "arrow":
        values = frames_by_arrow(block, n_frames, n_channels)
    if values is None:
        values = frames_by_line(text.split("\n"), cursor.number + 1, n_frames, n_channels, path)
    return _motion_from_channels(hierarchy, values, 1.0 / frame_time, root_translation, length_unit)


def _sections(text: str, path: str) -> tuple[Hierarchy, _LineCursor]:
    """The hierarchy, and a cursor on the MOTION line."""
    match = _MOTION.search(text)
    if match is None:
        # The hierarchy read to the end names a truncation, or stray text where MOTION belongs.
        parse_hierarchy(text.split("\n"), path, "end of file (truncated file?)")
        last_line = text.count("\n", 0, len(text.rstrip())) + 1
        raise ParseError("Expected a 'MOTION' section, got end of file", path, last_line)
    motion_line = text.count("\n", 0, match.start())  # 0-based index of the MOTION line
    if not text[: match.start()].strip():
        raise ParseError(
            "Expected a 'HIERARCHY' section before 'MOTION', got 'MOTION' first",
            path,
            motion_line + 1,
        )
    hierarchy = parse_hierarchy(
        text[: match.start()].split("\n"), path, "end of hierarchy (truncated file?)"
    )
    return hierarchy, _LineCursor(text, match.end(), motion_line)


_Number = TypeVar("_Number", int, float)


def _header_number(
    cursor: _LineCursor,
    pattern: re.Pattern[str],
    key: str,
    number: Callable[[str], _Number],
    expected: str,
    path: str,
) -> tuple[_Number, str]:
    """The number on the next non-blank line, ``key`` followed by it, and its text.

    Raises
    ------
    ParseError
        At the end of the file, on another line, or when ``number`` refuses the value
        ("Expected ``expected``, got ...").
    """
    line = cursor.next_nonblank()
    if line is None:
        raise ParseError(f"Expected {key!r}, got end of file", path, cursor.number + 1)
    text = _header_value(line, pattern, key, path, cursor.number + 1)
    try:
        return number(text), text
    except ValueError:
        raise ParseError(
            f"Expected {expected}, got {quoted(text)}", path, cursor.number + 1
        ) from None


def _motion_header(cursor: _LineCursor, path: str) -> tuple[int, float]:
    """The ``Frames:`` count and the ``Frame Time:`` (seconds) below MOTION."""
    n_frames, _ = _header_number(cursor, _FRAMES, "Frames:", int, "a frame count", path)
    if n_frames < 0:
        raise ParseError(f"Expected a frame count >= 0, got {n_frames}", path, cursor.number + 1)
    frame_time, time_text = _header_number(
        cursor, _FRAME_TIME, "Frame Time:", float, "a frame time in seconds", path
    )
    _check_frame_time(frame_time, time_text, path, cursor.number + 1)
    return n_frames, frame_time


def _motion_from_channels(
    hierarchy: Hierarchy,
    values: FloatArray,
    fps: float,
    root_translation: Literal["auto", "replace", "add"],
    length_unit: str,
) -> Motion:
    n_frames = values.shape[0]
    n_joints = len(hierarchy.names)
    translations = np.zeros((n_frames, n_joints, 3))
    by_order: dict[str, list[tuple[int, list[int]]]] = {}
    # Position channels: (column, joint, axis), copied in one gather and one scatter.
    position_columns: list[tuple[int, int, int]] = []
    column = 0
    for j, chans in enumerate(hierarchy.channels):
        rot_cols: list[int] = []
        order = ""
        for k, channel in enumerate(chans):
            if channel in POSITION_CHANNELS:
                position_columns.append((column + k, j, "XYZ".index(channel[0])))
            else:
                rot_cols.append(column + k)
                order += channel[0]
        if order:
            by_order.setdefault(order, []).append((j, rot_cols))
        column += len(chans)
    if position_columns:
        where = np.array(position_columns, dtype=np.intp).T
        translations[:, where[1], where[2]] = values[:, where[0]]
    all_rotating = sum(len(entries) for entries in by_order.values()) == n_joints
    if len(by_order) == 1 and all_rotating:
        # One rotation order on every joint (the usual case): no identity fill, no scatter.
        ((order, entries),) = by_order.items()
        euler_deg = np.take(values, np.array([c for _, c in entries]), axis=1)  # (F, J, 3)
        quats = quats_from_euler(euler_deg, order, degrees=True)
    else:
        quats = np.zeros((n_frames, n_joints, 4))
        quats[..., 3] = 1.0
        euler_deg = np.zeros((n_frames, n_joints, 3))
        for order, entries in by_order.items():
            joints = [j for j, _ in entries]
            angles_deg = values[:, np.array([c for _, c in entries])]  # (F, n, 3)
            euler_deg[:, joints] = angles_deg
            quats[:, joints] = quats_from_euler(angles_deg, order, degrees=True)
    offsets = np.array(hierarchy.offsets, dtype=np.float64).reshape(n_joints, 3)
    mode = root_translation
    if mode == "auto":
        mode = _detect_root_translation(hierarchy, offsets, translations)
    skeleton = Skeleton(
        names=tuple(hierarchy.names),
        parents=np.array(hierarchy.parents, dtype=np.intp),
        offsets=offsets,
        channels=tuple(hierarchy.channels),
        end_sites=tuple(hierarchy.end_sites),
        length_unit=length_unit,
        root_translation=mode,
    )
    if not math.isfinite(fps):
        # A subnormal Frame Time: the checked constructor reports it.
        return Motion(skeleton, quats, translations, fps, euler_hint_deg=euler_deg)
    # Every array was built here from finite values (both number readers reject NaN and
    # infinity) with the skeleton's shapes, and the quaternions are unit by construction, so
    # the constructor's conversions and norm check would only repeat work.
    return Motion._from_valid_arrays(skeleton, quats, translations, fps, euler_deg)


def _detect_root_translation(
    hierarchy: Hierarchy, offsets: FloatArray, translations: FloatArray
) -> Literal["replace", "add"]:
    root_offset = offsets[0]
    has_pos = any(c in POSITION_CHANNELS for c in hierarchy.channels[0])
    if not has_pos or not np.any(root_offset) or translations.shape[0] == 0:
        return "replace"
    # Along the OFFSET's dominant axis (the height, for a hip root), deltas sit near zero while
    # absolute positions sit near the rest OFFSET.
    axis = int(np.argmax(np.abs(root_offset)))
    median = float(np.median(np.abs(translations[:, 0, axis])))
    return "add" if median < 0.25 * abs(float(root_offset[axis])) else "replace"


def read_bvh(
    path: str | Path,
    root_translation: Literal["auto", "replace", "add"] = "auto",
    length_unit: str = "unknown",
    number_reader: NumberReader = "arrow",
) -> Motion:
    """Read a BVH file. See :func:`parse_bvh` for parameters and errors."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as e:
        raise ParseError(f"Expected a readable file, got {e.strerror}", path) from e
    return parse_bvh(
        data,
        path,
        root_translation=root_translation,
        length_unit=length_unit,
        number_reader=number_reader,
    )
