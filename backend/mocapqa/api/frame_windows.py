"""Windows of a run's stored points (``points.npz``), as JSON or as packed float32.

The 3D views read a decimated overview of the whole take and, when paused, a full-rate window
around the current frame. JSON costs the server ``tolist`` and ``json.dumps`` and the browser a
parse of every number; the packed form is the arrays' bytes after a short JSON header.
"""

from __future__ import annotations

import json
import struct
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np

from mocapqa.errors import OptionError, ShapeError
from mocapqa.jobs.run_folder import POINT_ARRAYS

__all__ = ["MAX_WINDOW_VALUES", "Window", "read_window", "window_json", "window_packed"]

MAX_WINDOW_VALUES = 3_000_000
"""Most values (frames × points × components, over every array) one window may hold; the
step grows until a window fits."""
READ_BLOCK_BYTES = 8 * 2**20
"""Most bytes of one stored array held at once while a window's rows are picked from it."""


@dataclass(frozen=True)
class Window:
    """Frames ``frames`` of a run's points.

    Attributes
    ----------
    frames : ndarray, shape (F,)
        The frame indices held, ``start, start + step, …``.
    n_frames : int
        Frames in the take.
    step : int
        Frames between two held frames.
    arrays : dict of str to ndarray
        ``raw`` and ``corrected`` (F, P, 3) positions in file units (NaN where missing); motion
        takes ``raw_rotations`` and ``corrected_rotations`` (F, P, 4) world unit quaternions,
        scalar-last; keypoint takes ``confidence`` (F, P) in 0–1 and, when filtered,
        ``bridged`` (F, P), 1 where the filter had no valid input; marker takes checked by the
        markers step ``filled`` (F, P), 1 on samples a gap fill wrote.
    """

    frames: np.ndarray
    n_frames: int
    step: int
    arrays: dict[str, np.ndarray]


def read_window(path: Path, start: int, stop: int | None, step: int, max_frames: int) -> Window:
    """Frames ``start:stop:step`` of ``points.npz``, the step grown to fit the window's limits.

    The step grows until at most ``max_frames`` frames and at most :data:`MAX_WINDOW_VALUES`
    values come back, so a window is always served, coarser where the take is long or holds
    many points. Only the array headers are read before the window is chosen, and then only
    the bytes up to the window's last frame of each array.

    Raises
    ------
    OptionError
        Naming ``start`` when it is at or past the take's last frame, ``stop`` when it is not
        above ``start``, ``max_frames`` when one frame alone holds more than
        :data:`MAX_WINDOW_VALUES` values.
    """
    with zipfile.ZipFile(path) as archive:
        members = {
            name: f"{name}.npy" for name in POINT_ARRAYS if f"{name}.npy" in archive.namelist()
        }
        shapes = {name: _member_shape(archive, member) for name, member in members.items()}
        frames, step = _window_frames(shapes, start, stop, step, max_frames)
        arrays = {name: _member_rows(archive, member, frames) for name, member in members.items()}
    return Window(frames, int(shapes["raw"][0]), step, arrays)


def _window_frames(
    shapes: dict[str, tuple[int, ...]], start: int, stop: int | None, step: int, max_frames: int
) -> tuple[np.ndarray, int]:
    """The frame indices of a window and its step, grown to fit both limits."""
    n_frames = int(shapes["raw"][0])
    if start >= n_frames:
        raise OptionError(
            "start", f"Expected start below the take's {n_frames} frames, got {start}"
        )
    if stop is not None and stop <= start:
        raise OptionError("stop", f"Expected stop above start ({start}), got {stop}")
    stop = n_frames if stop is None else min(stop, n_frames)
    per_frame = sum(int(np.prod(shape[1:])) for shape in shapes.values())
    most = min(max_frames, MAX_WINDOW_VALUES // max(per_frame, 1))
    if most < 1:
        raise OptionError(
            "max_frames",
            f"Expected a frame of at most {MAX_WINDOW_VALUES} values (points × components over "
            f"every array), got {per_frame}: this take's frames are too large to serve",
        )
    if -(-(stop - start) // step) > most:
        step = -(-(stop - start) // most)
    return np.arange(start, stop, step), step


def _member_shape(archive: zipfile.ZipFile, member: str) -> tuple[int, ...]:
    """The shape an ``.npy`` member of an archive declares, read from its header alone."""
    with archive.open(member) as handle:
        header = _npy_header(handle)
        if header is None:
            return tuple(int(n) for n in np.lib.format.read_array(handle).shape)
        return header[0]


def _npy_header(handle: IO[bytes]) -> tuple[tuple[int, ...], bool, np.dtype[Any]] | None:
    """Shape, Fortran order and dtype of an ``.npy`` stream, the stream left at its data.

    None (the stream rewound) for a header version this reader leaves to numpy.
    """
    version = np.lib.format.read_magic(handle)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(handle)
    elif version == (2, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(handle)
    else:
        handle.seek(0)
        return None
    return tuple(int(n) for n in shape), bool(fortran), dtype


def _member_rows(archive: zipfile.ZipFile, member: str, frames: np.ndarray) -> np.ndarray:
    """Rows ``frames`` (ascending) of an ``.npy`` member, reading up to the last one only.

    The bytes before the last frame are read in blocks of at most :data:`READ_BLOCK_BYTES`
    and the wanted rows kept, so memory holds one block and the window, never the array.
    """
    with archive.open(member) as handle:
        header = _npy_header(handle)
        if header is None or header[1] or header[2].hasobject:
            handle.seek(0)
            return np.asarray(np.lib.format.read_array(handle)[frames])
        shape, _, dtype = header
        row_bytes = int(np.prod(shape[1:])) * dtype.itemsize
        first, last = int(frames[0]), int(frames[-1])
        handle.seek(handle.tell() + first * row_bytes)
        block_rows = max(1, READ_BLOCK_BYTES // max(row_bytes, 1))
        parts = []
        for block_start in range(first, last + 1, block_rows):
            count = min(block_rows, last + 1 - block_start)
            data = handle.read(count * row_bytes)
            if len(data) != count * row_bytes:
                raise ShapeError(f"Expected {count} rows of {member}, got a truncated array")
            block = np.frombuffer(data, dtype).reshape(count, *shape[1:])
            inside = frames[(frames >= block_start) & (frames < block_start + count)]
            parts.append(block[inside - block_start])
        return np.concatenate(parts)


def window_json(window: Window) -> bytes:
    """The window as JSON: ``frames``, ``n_frames``, ``step`` and the arrays as nested lists.

    Positions and rotations are rounded to 3 decimals, confidence to 2; ``bridged`` and
    ``filled`` are 0/1.
    A missing point is ``[null, null, null]``.
    """
    payload: dict[str, object] = {
        "frames": window.frames.tolist(),
        "n_frames": window.n_frames,
        "step": window.step,
    }
    for name, values in window.arrays.items():
        if name in ("bridged", "filled"):
            payload[name] = values.astype(np.int8).tolist()
        else:
            digits = 2 if name == "confidence" else 3
            payload[name] = np.round(values.astype(np.float64), digits).tolist()
    # Plain json.dumps: FastAPI's encoder would walk each of the ~10^5 numbers in Python.
    # Missing points are NaN in the store; JSON has no NaN, so they go out as null (no number
    # literal contains "NaN", so the replacement touches nothing else).
    return json.dumps(payload, separators=(",", ":")).replace("NaN", "null").encode()


def window_packed(window: Window) -> bytes:
    """The window as one binary message the browser reads into ``Float32Array`` views.

    Layout: a little-endian uint32 ``n``; ``n`` bytes of UTF-8 JSON header (``start``,
    ``step``, ``count``, ``n_frames``, ``points`` and ``arrays``: ``[name, components]`` in the
    order they follow), padded with spaces to a multiple of 4 bytes; then each array as
    little-endian float32, C order, shape (count, points, components). Missing points are NaN.
    """
    first = next(iter(window.arrays.values()))
    header = {
        "start": int(window.frames[0]),
        "step": window.step,
        "count": int(window.frames.size),
        "n_frames": window.n_frames,
        "points": int(first.shape[1]),
        "arrays": [[name, int(np.prod(a.shape[2:]))] for name, a in window.arrays.items()],
    }
    text = json.dumps(header, separators=(",", ":")).encode()
    text += b" " * (-(4 + len(text)) % 4)
    parts = [struct.pack("<I", len(text)), text]
    parts += [np.ascontiguousarray(a, dtype="<f4").tobytes() for a in window.arrays.values()]
    return b"".join(parts)
