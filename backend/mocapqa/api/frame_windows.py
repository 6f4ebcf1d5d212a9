"""Windows of a run's stored points (``points.npz``), as JSON or as packed float32.

The 3D views read a decimated overview of the whole take and, when paused, a full-rate window
around the current frame. JSON costs the server ``tolist`` and ``json.dumps`` and the browser a
parse of every number; the packed form is the arrays' bytes after a short JSON header.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.errors import InputError
from mocapqa.jobs.run_folder import POINT_ARRAYS

__all__ = ["MAX_WINDOW_VALUES", "Window", "read_window", "window_json", "window_packed"]

MAX_WINDOW_VALUES = 3_000_000
"""Most values (frames × points × components, over every array) one window may hold."""


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
    """Frames ``start:stop:step`` of ``points.npz``, the step grown to hold ≤ ``max_frames``.

    Raises
    ------
    InputError
        When ``start ≥ stop`` or the window would exceed :data:`MAX_WINDOW_VALUES`.
    """
    with np.load(path) as data:
        stored = {name: data[name] for name in POINT_ARRAYS if name in data}
    n_frames = int(stored["raw"].shape[0])
    stop = n_frames if stop is None else min(stop, n_frames)
    if start >= stop:
        raise InputError(f"Expected start < stop ≤ {n_frames}, got start={start}, stop={stop}")
    if -(-(stop - start) // step) > max_frames:
        step = -(-(stop - start) // max_frames)
    frames = np.arange(start, stop, step)
    per_frame = sum(int(np.prod(a.shape[1:])) for a in stored.values())
    if frames.size * per_frame > MAX_WINDOW_VALUES:
        raise InputError(
            f"Expected a window of at most {MAX_WINDOW_VALUES} values, got {frames.size} frames"
        )
    return Window(frames, n_frames, step, {name: a[frames] for name, a in stored.items()})


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
