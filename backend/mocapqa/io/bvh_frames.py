"""Reading the frame block of a BVH file: a fast path and a line-by-line path.

Conventions
-----------
* :func:`frames_by_arrow` reads the whole block with pyarrow's CSV reader (correctly rounded,
  like ``float``) and returns None on anything unexpected, never raising.
* :func:`frames_by_line` is the reference path: ``float`` per token, one line at a time, and
  the only one that raises, with the 1-based line.
* Lines are counted by LF; CR is whitespace.
"""

from __future__ import annotations

import functools
import importlib
import math
from itertools import repeat
from operator import add
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.bounds import MAX_MAGNITUDE
from mocapqa.errors import ParseError

__all__ = ["frames_by_arrow", "frames_by_line", "quoted"]


_QUOTED_CHARS = 40


def quoted(text: str) -> str:
    """``text`` quoted for an error message, cut to 40 characters (a hostile file's token
    may be megabytes long)."""
    if len(text) > _QUOTED_CHARS:
        return repr(text[:_QUOTED_CHARS]) + "…"
    return repr(text)


_TOKEN_SHAPES = bytes(
    byte if byte == 10 else 32 if byte in b" \t\r" else ord("x") for byte in range(256)
)
_SPACES_TO_NEWLINES = bytes.maketrans(b" \t\r", b"\n\n\n")


def frames_by_arrow(block: str, n_frames: int, n_channels: int) -> FloatArray | None:
    """Parse the frame block with Arrow's CSV reader; None when it needs the careful path.

    Parameters
    ----------
    block : str
        The text after the ``Frame Time:`` line.
    n_frames, n_channels : int
        The counts the header announced.

    Returns
    -------
    ndarray, shape (n_frames, n_channels), or None
        None when pyarrow is missing or anything is off (then :func:`frames_by_line`
        reports the problem with its line).

    The usual layout (single spaces, one frame per line) is read as a table of one column
    per channel (:func:`_frames_by_columns`). Otherwise every whitespace becomes a line
    break, so Arrow reads one float column, and the line structure is checked separately.
    Arrow's parser is correctly rounded, like ``float``, and its CSV module imports in
    ~0.04 s, unlike pandas (~0.3 s), so even one small file gains. The returned array may be
    read-only (a view of Arrow's memory).
    """
    if n_frames == 0 or n_channels == 0:
        return None
    try:
        raw = block.encode("ascii")
    except UnicodeEncodeError:
        return None
    arrow, arrow_csv = _arrow()
    if arrow is None:
        return None
    columns = _frames_by_columns(arrow, arrow_csv, raw, n_frames, n_channels)
    if columns is not None:
        return columns
    # Every non-blank line must hold exactly n_channels values: count token starts per line
    # on a copy where whitespace is " " and anything else "x".
    # A value starts at each " x" and at an "x" opening a line.
    lines = raw.translate(_TOKEN_SHAPES).split(b"\n")
    counts = list(
        map(add, map(bytes.count, lines, repeat(b" x")), map(bytes.startswith, lines, repeat(b"x")))
    )
    if not set(counts) <= {0, n_channels}:
        return None
    n_tokens = sum(counts)
    if n_tokens != n_frames * n_channels:
        return None
    try:
        table = arrow_csv.read_csv(
            arrow.BufferReader(raw.translate(_SPACES_TO_NEWLINES)),
            read_options=arrow_csv.ReadOptions(column_names=["value"], use_threads=False),
            parse_options=arrow_csv.ParseOptions(
                quote_char=False, escape_char=False, ignore_empty_lines=True
            ),
            convert_options=arrow_csv.ConvertOptions(
                column_types={"value": arrow.float64()},
                null_values=[],
                strings_can_be_null=False,
                quoted_strings_can_be_null=False,
            ),
        )
        column = _float_column(table.column(0))
    except (arrow.ArrowException, ValueError):
        return None
    if column is None or column.shape != (n_tokens,) or not _in_range(column):
        return None
    return column.reshape(n_frames, n_channels)


def _arrow() -> tuple[Any, Any]:
    """pyarrow and pyarrow.csv, or (None, None) when pyarrow is not installed."""
    try:
        return importlib.import_module("pyarrow"), importlib.import_module("pyarrow.csv")
    except ImportError:
        return None, None


def _frames_by_columns(
    arrow: Any, arrow_csv: Any, raw: bytes, n_frames: int, n_channels: int
) -> FloatArray | None:
    """The common layout, one frame per line and one space between values, read as a table.

    Arrow checks the layout itself: a line with another value count, a doubled or leading
    space (an empty field) or a non-number fails the read, and the caller falls back. One
    trailing space per line is allowed and must leave the extra column empty on every line.
    About 3× faster than one value per row, as the per-row cost is paid once per frame.
    """
    end = raw.find(b"\n")
    first = raw[: end if end >= 0 else len(raw)].rstrip(b"\r")
    if b"\t" in raw[:4096] or _has_lone_cr(raw):
        return None  # tabs; Arrow would end a line at a lone CR, BVH lines end only at LF
    trailing = first.endswith(b" ")
    read_options, parse_options, convert_options = _table_options(n_channels, trailing)
    try:
        table = arrow_csv.read_csv(
            arrow.BufferReader(raw),
            read_options=read_options,
            parse_options=parse_options,
            convert_options=convert_options,
        )
        if table.num_rows != n_frames:
            return None
        if trailing and any(map(_has_text, table.column(n_channels).chunks)):
            return None
        # One C++ call per batch (a loop over columns costs ~5 µs each); nulls raise.
        batches = table.select(list(range(n_channels))).to_batches()
        blocks = [
            np.asarray(batch.to_tensor(null_to_nan=False, row_major=True)) for batch in batches
        ]
        values: FloatArray = blocks[0] if len(blocks) == 1 else np.concatenate(blocks)
    except (arrow.ArrowException, ValueError):
        return None
    if values.shape != (n_frames, n_channels) or not _in_range(values):
        return None
    return values


def _in_range(values: FloatArray) -> bool:
    """Whether every value is finite and within :data:`MAX_MAGNITUDE` (NaN is not)."""
    return bool(np.all(np.abs(values) <= MAX_MAGNITUDE))


@functools.lru_cache(maxsize=64)
def _table_options(n_channels: int, trailing: bool) -> tuple[Any, Any, Any]:
    """Arrow's read, parse and convert options for one channel count (~0.08 ms to build).

    Columns are named by their index; with ``trailing``, one more (string) column takes the
    empty field after a trailing space.
    """
    arrow, arrow_csv = _arrow()
    names = [str(i) for i in range(n_channels + 1 if trailing else n_channels)]
    types = dict.fromkeys(names[:n_channels], arrow.float64())
    if trailing:
        types[names[-1]] = arrow.string()
    return (
        # One thread: Arrow's pool converts columns in parallel, ~1.6× faster back to back,
        # but waking its threads after a pause costs more than that gains on a take of this
        # size, and a server reads several takes at once anyway.
        arrow_csv.ReadOptions(column_names=names, use_threads=False),
        arrow_csv.ParseOptions(
            delimiter=" ", quote_char=False, escape_char=False, ignore_empty_lines=True
        ),
        arrow_csv.ConvertOptions(
            column_types=types,
            null_values=[],
            strings_can_be_null=False,
            quoted_strings_can_be_null=False,
        ),
    )


def _has_lone_cr(raw: bytes) -> bool:
    """Whether a CR stands anywhere but right before an LF (~0.1 ms for 0.5 MB)."""
    if b"\r" not in raw:
        return False
    data = np.frombuffer(raw, np.uint8)
    after = np.flatnonzero(data == 13) + 1
    return bool(after[-1] == data.size or np.any(data[after] != 10))


def _has_text(chunk: Any) -> bool:
    """Whether a chunk of an Arrow string column holds any non-empty string."""
    offsets = np.frombuffer(
        chunk.buffers()[1], np.int32, count=len(chunk) + 1, offset=4 * chunk.offset
    )
    return bool(offsets[-1] != offsets[0])


def _float_column(column: Any) -> FloatArray | None:
    """A float64 Arrow column as numpy, or None if it holds nulls.

    Straight from the buffers: Arrow's ``to_numpy()`` imports pandas (~0.3 s).
    """
    parts = []
    for chunk in column.chunks:
        if chunk.null_count:
            return None
        data = chunk.buffers()[1]
        parts.append(np.frombuffer(data, np.float64, count=len(chunk), offset=8 * chunk.offset))
    return np.concatenate(parts) if parts else np.zeros(0)


def frames_by_line(
    lines: list[str], first: int, n_frames: int, n_channels: int, path: str
) -> FloatArray:
    """Parse frame lines one by one with ``float``, raising on the first bad line.

    Parameters
    ----------
    lines : list of str
        The file's lines (split on LF).
    first : int
        0-based index of the first frame line.
    n_frames, n_channels : int
        The counts the header announced.
    path : str
        File name for error messages.

    Returns
    -------
    ndarray, shape (n_frames, n_channels)

    Raises
    ------
    ParseError
        On a wrong value count, a non-number, NaN or infinity, a value beyond
        :data:`MAX_MAGNITUDE`, or too few or too many lines, with the 1-based line.
    """
    # Rows are collected, not preallocated: a corrupt "Frames:" count must not allocate.
    rows: list[list[float]] = []
    row = 0
    last = first - 1  # 0-based index of the last frame line read
    for number in range(first, len(lines)):
        tokens = lines[number].split()
        if not tokens:
            continue
        last = number
        if row >= n_frames:
            raise ParseError(
                f"Expected {n_frames} frame lines (Frames:), got more", path, number + 1
            )
        if len(tokens) != n_channels:
            cut = len(tokens) < n_channels and not any(map(str.strip, lines[number + 1 :]))
            raise ParseError(
                f"Expected {n_channels} values on a frame line, got {len(tokens)}"
                + (" (truncated file?)" if cut else ""),
                path,
                number + 1,
            )
        try:
            parsed = list(map(float, tokens))
        except ValueError:
            bad = next(t for t in tokens if not _is_float(t))
            raise ParseError(f"Expected a number, got {quoted(bad)}", path, number + 1) from None
        if not all(map(math.isfinite, parsed)):
            raise ParseError("Expected finite numbers, got NaN or infinity", path, number + 1)
        if max(map(abs, parsed), default=0.0) > MAX_MAGNITUDE:
            bad = next(t for t, v in zip(tokens, parsed, strict=True) if abs(v) > MAX_MAGNITUDE)
            raise ParseError(
                f"Expected values within ±{int(MAX_MAGNITUDE):,}, got {quoted(bad)}",
                path,
                number + 1,
            )
        rows.append(parsed)
        row += 1
    if row != n_frames:
        # Reported at the line where the next frame was expected.
        raise ParseError(
            f"Expected {n_frames} frame lines (Frames:), got {row} (truncated file?)",
            path,
            last + 2,
        )
    return np.array(rows, dtype=np.float64).reshape(n_frames, n_channels)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
