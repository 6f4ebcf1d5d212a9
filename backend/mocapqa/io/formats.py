"""Format detection and dispatch for takes: BVH motions and keypoint sequences.

Conventions
-----------
* :func:`detect_format` looks at the extension first (``.c3d`` in any case; a C3D without it is
  known by its second byte, 0x50, after a parameter block number of 2 or more) and sniffs the
  content to tell the variants apart (OpenPose, MediaPipe or generic JSON; MediaPipe or
  generic CSV); a file with an unknown extension is sniffed by its first bytes. A folder of
  OpenPose JSON is "openpose".
* :func:`read_take` returns a :class:`~mocapqa.core.motion.Motion` for BVH and a
  :class:`~mocapqa.core.keypoints.KeypointSequence` for every keypoint format (a C3D's points:
  :func:`mocapqa.io.c3d.read_c3d` gives the residuals, events and analogs too). ``fps`` and
  ``length_unit`` are used only where a format does not store them (see each reader).
* :func:`write_keypoints` picks the writer from the extension (or ``format``); a ``.c3d``
  written from a keypoint sequence has its points only (residual 0 where present, −1 where
  missing): ``mocapqa convert`` of a C3D writes with :func:`mocapqa.io.c3d.write_c3d` and the
  source instead, keeping analogs and parameters.
* Unknown formats raise :class:`~mocapqa.errors.UnsupportedFormatError`.
"""

from __future__ import annotations

import codecs
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import numpy as np

from mocapqa.core.bounds import MAX_FPS, MIN_FPS
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError, ParseError, UnsupportedFormatError
from mocapqa.io.bvh import NumberReader, read_bvh
from mocapqa.io.c3d import MarkerTake, read_c3d, write_c3d
from mocapqa.io.guards import ReadLimits, check_take_input, check_take_size
from mocapqa.io.keypoint_arrays import (
    read_keypoint_npy,
    read_keypoint_npz,
    write_keypoint_npy,
    write_keypoint_npz,
)
from mocapqa.io.keypoint_csv import read_keypoint_csv, write_keypoint_csv
from mocapqa.io.keypoint_input import check_coordinates
from mocapqa.io.keypoint_json import read_keypoint_json, write_keypoint_json
from mocapqa.io.mediapipe import read_mediapipe_csv, read_mediapipe_json, read_mediapipe_pbtxt
from mocapqa.io.openpose import openpose_frame_files, read_openpose
from mocapqa.io.trc import read_trc, write_trc

__all__ = [
    "KEYPOINT_FORMATS",
    "KEYPOINT_WRITE_FORMATS",
    "TAKE_FORMATS",
    "check_fps",
    "detect_format",
    "read_take",
    "require_frames",
    "write_keypoints",
]

# Names of the keypoint formats that detect_format can return.
KEYPOINT_FORMATS: tuple[str, ...] = (
    "trc",
    "openpose",
    "mediapipe-csv",
    "mediapipe-json",
    "mediapipe-pbtxt",
    "csv",
    "npy",
    "npz",
    "json",
)
# Every format read_take accepts: a C3D's markers are read as keypoints.
TAKE_FORMATS: tuple[str, ...] = ("bvh", *KEYPOINT_FORMATS, "c3d")
# Formats write_keypoints can write, by file extension.
KEYPOINT_WRITE_FORMATS: tuple[str, ...] = ("trc", "csv", "npy", "npz", "json", "c3d")

_SNIFF_BYTES = 4096
_PARSE_TO_DETECT_BYTES = 1_000_000
_BY_EXTENSION = {
    ".bvh": "bvh",
    ".trc": "trc",
    ".npy": "npy",
    ".npz": "npz",
    ".pbtxt": "mediapipe-pbtxt",
    ".c3d": "c3d",
}


def _head(path: Path) -> bytes:
    try:
        with path.open("rb") as handle:
            return handle.read(_SNIFF_BYTES)
    except OSError as e:
        raise ParseError(f"Expected a readable file, got {e.strerror or e}", path) from e


def _json_kind(path: Path) -> str:
    head = _head(path)
    text = head.decode("utf-8", errors="replace")
    if '"people"' in text:
        return "openpose"
    if '"keypoints"' in text:
        return "json"
    if '"visibility"' in text or '"landmarks"' in text:
        return "mediapipe-json"
    try:
        if path.stat().st_size > _PARSE_TO_DETECT_BYTES:
            # Not parsed to be told apart (that would cost what the read limits guard):
            # a list, or an object with no "keypoints" key anywhere, is MediaPipe's.
            data = path.read_bytes()
            top_is_list = data.lstrip(b"\xef\xbb\xbf \t\r\n")[:1] == b"["
            return "mediapipe-json" if top_is_list or b'"keypoints"' not in data else "json"
        document: Any = json.loads(path.read_bytes())
    except (OSError, ValueError, RecursionError):
        return "json"
    if isinstance(document, list) or (isinstance(document, dict) and "keypoints" not in document):
        return "mediapipe-json"
    return "json"


def _csv_kind(head: bytes) -> str:
    lines = [ln for ln in head.decode("utf-8", errors="replace").splitlines() if ln.strip()]
    header = next((ln for ln in lines if not ln.startswith("#")), "").lower()
    columns = [c.strip() for c in header.split(",")]
    return "mediapipe-csv" if "frame_number" in columns and "landmark" in columns else "csv"


def _utf16_bvh(head: bytes) -> bool:
    """Whether ``head`` is the start of a BVH saved as UTF-16 with its byte order mark."""
    if head[:2] not in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE):
        return False
    text = head[: len(head) // 2 * 2].decode("utf-16", errors="replace")
    return text.lstrip(" \t\r\n")[:9].upper() == "HIERARCHY"


def _sniff(path: Path) -> str | None:
    head = _head(path)
    stripped = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    if stripped[:9].upper() == b"HIERARCHY" or _utf16_bvh(head):
        return "bvh"
    if stripped.startswith(b"PathFileType"):
        return "trc"
    if head.startswith(b"\x93NUMPY"):
        return "npy"
    if head.startswith(b"PK\x03\x04"):
        return "npz"
    if len(head) >= 512 and head[1] == 0x50 and head[0] >= 2:
        return "c3d"
    if stripped[:1] in (b"{", b"["):
        return _json_kind(path)
    if stripped.startswith(b"# proto-") or stripped.startswith(b"landmarks {"):
        return "mediapipe-pbtxt"
    first = stripped.split(b"\n", 1)[0].lower()
    if b"," in first and (b"frame" in first or stripped.startswith(b"#")):
        return _csv_kind(head)
    return None


def detect_format(path: str | Path, display_name: str | None = None) -> str:
    """Name the format of a take file or folder.

    Parameters
    ----------
    path : str or Path
        A file, or a folder of OpenPose JSON frames.
    display_name : str, optional
        The name the user knows the file by, for the error (an upload is read from a
        temporary file); the path's own name when omitted.

    Returns
    -------
    str
        One of :data:`TAKE_FORMATS`: "bvh", "trc", "openpose", "mediapipe-csv",
        "mediapipe-json", "mediapipe-pbtxt", "csv", "npy", "npz", "json" or "c3d".

    Raises
    ------
    ParseError
        When the path cannot be read.
    UnsupportedFormatError
        When neither the extension nor the content names a supported format.
    """
    path = Path(path)
    if path.is_dir():
        files = openpose_frame_files(path)
        if _json_kind(files[0]) == "openpose":
            return "openpose"
        raise UnsupportedFormatError(
            f"Expected a folder of OpenPose JSON frames, got JSON without 'people' in {path}"
        )
    if not path.exists():
        raise ParseError("Expected an existing file or folder, got nothing there", path)
    suffix = path.suffix.lower()
    if suffix in _BY_EXTENSION:
        return _BY_EXTENSION[suffix]
    if suffix == ".json":
        return _json_kind(path)
    if suffix == ".csv":
        return _csv_kind(_head(path))
    found = _sniff(path)
    if found is None:
        raise UnsupportedFormatError(
            f"Expected one of {', '.join(TAKE_FORMATS)} (by extension or content), "
            f"got an unrecognised file {display_name or path.name!r}"
        )
    return found


def read_take(
    path: str | Path,
    fps: float | None = None,
    person_index: int = 0,
    length_unit: str | None = None,
    number_reader: NumberReader = "arrow",
    root_translation: Literal["auto", "add", "replace"] = "auto",
    limits: ReadLimits | None = None,
) -> Motion | KeypointSequence:
    """Read a take of any supported format.

    Parameters
    ----------
    path : str or Path
        The file or OpenPose folder.
    fps : float, optional
        Frames per second for formats that do not store it (OpenPose, MediaPipe, NPY, CSV
        without time); ignored by BVH and TRC, which store their own.
    person_index : int
        Person to read from OpenPose output.
    length_unit : str, optional
        Unit for formats that do not store one.
    number_reader : {"arrow", "python", "auto"}
        How BVH frame values are read (see :func:`mocapqa.io.bvh.parse_bvh`); "auto" suits
        a one-off read in a fresh process.
    root_translation : {"auto", "add", "replace"}
        How a BVH root's position channels combine with its OFFSET (see
        :mod:`mocapqa.io.bvh_root`); ignored by keypoint formats.
    limits : ReadLimits, optional
        Refuse takes beyond these limits, before reading where the bytes tell (see
        :mod:`mocapqa.io.guards`); no limits when None (trusted local files).

    Returns
    -------
    Motion or KeypointSequence
        A Motion for BVH, a KeypointSequence otherwise.

    Raises
    ------
    ParseError
        On unreadable or malformed input.
    UnsupportedFormatError
        On an unknown format.
    TooLargeError
        When the take exceeds ``limits``.
    """
    kind = detect_format(path)
    if limits is None:
        return _read(path, kind, fps, person_index, length_unit, number_reader, root_translation)
    check_take_input(path, kind, limits)
    try:
        take = _read(
            path, kind, fps, person_index, length_unit, number_reader, root_translation, limits
        )
    except RecursionError as e:  # a backstop: the depth check above refuses such files first
        raise ParseError("Expected a shallower document, got one nested too deep", path) from e
    if isinstance(take, Motion):
        check_take_size(take.n_frames, take.skeleton.n_joints, Path(path).name, limits)
    else:
        check_take_size(take.n_frames, take.n_keypoints, Path(path).name, limits)
    return take


def check_fps(fps: float, name: str = "fps") -> None:
    """Refuse a frame rate the user gives (``--fps``, an upload's ``fps``, a live stream's)
    that is not finite, from :data:`~mocapqa.core.bounds.MIN_FPS` to
    :data:`~mocapqa.core.bounds.MAX_FPS`.

    Parameters
    ----------
    fps : float
        The rate, frames per second.
    name : str
        The option or field named in the message.

    Raises
    ------
    InputError
        E.g. ``Expected --fps finite, at least 0.1 and at most 100000 frames per second, got
        inf``.
    """
    if not (math.isfinite(fps) and MIN_FPS <= fps <= MAX_FPS):
        raise InputError(
            f"Expected {name} finite, at least {MIN_FPS:g} and at most {MAX_FPS:g} frames per "
            f"second, got {fps:g}"
        )


def require_frames(take: Motion | KeypointSequence, path: str | Path) -> None:
    """Refuse a take without frames (a BVH's ``Frames: 0``): nothing to analyse or draw.

    Readers accept such a take, so ``mocapqa info`` and ``convert`` work on a rig-only BVH;
    everything that analyses, filters or renders a take calls this first.

    Also refuses a keypoint take without keypoints, with a coordinate beyond ±1e9 (which the
    readers refuse already; a sequence made in code may hold one) or a frame rate below 0.1
    or over 100,000 fps (:mod:`mocapqa.core.bounds`: the limits a BVH's reader and ``--fps``
    already keep; a keypoint file's own rate, such as a JSON ``fps`` of 1e-300, meets them
    here).

    Raises
    ------
    ParseError
        Naming the file and the field (``Frames`` of a BVH, ``keypoints``, ``positions``,
        ``fps``).
    """
    if take.n_frames == 0:
        field = "Frames" if isinstance(take, Motion) else None
        raise ParseError("Expected at least one frame, got 0", path, field=field)
    if isinstance(take, KeypointSequence):
        if take.n_keypoints == 0:
            raise ParseError("Expected at least one keypoint, got 0", path, field="keypoints")
        check_coordinates(take.positions, path, take.names, take.frame_numbers)
        if not MIN_FPS <= take.fps <= MAX_FPS:
            raise ParseError(
                f"Expected fps at least {MIN_FPS:g} and at most {MAX_FPS:g}, got {take.fps:g}",
                path,
                field="fps",
            )


def _read(
    path: str | Path,
    kind: str,
    fps: float | None,
    person_index: int,
    length_unit: str | None,
    number_reader: NumberReader,
    root_translation: Literal["auto", "add", "replace"],
    limits: ReadLimits | None = None,
) -> Motion | KeypointSequence:
    if kind == "bvh":
        return read_bvh(
            path,
            root_translation=root_translation,
            length_unit=length_unit or "unknown",
            number_reader=number_reader,
        )
    if kind == "trc":
        return read_trc(path)
    if kind == "c3d":
        return read_c3d(path, limits).points
    if kind == "openpose":
        return read_openpose(path, fps=fps, person_index=person_index)
    if kind == "mediapipe-pbtxt":
        return read_mediapipe_pbtxt(path, fps=fps)
    if kind == "csv":  # the long CSVs check frames × points again before making their arrays
        return read_keypoint_csv(path, fps, length_unit, limits)
    if kind == "mediapipe-csv":
        return read_mediapipe_csv(path, fps, length_unit, limits)
    readers: dict[str, Callable[[Path, float | None, str | None], KeypointSequence]] = {
        "mediapipe-json": read_mediapipe_json,
        "npy": read_keypoint_npy,
        "npz": read_keypoint_npz,
        "json": read_keypoint_json,
    }
    return readers[kind](Path(path), fps, length_unit)


def write_keypoints(path: str | Path, seq: KeypointSequence, format: str | None = None) -> None:
    """Write a keypoint sequence, choosing the writer by ``format`` or the file extension.

    Parameters
    ----------
    path, seq : str or Path, KeypointSequence
        The destination file, and the data.
    format : str, optional
        One of :data:`KEYPOINT_WRITE_FORMATS`; default from the extension.

    Raises
    ------
    UnsupportedFormatError
        When the format (or extension) has no writer.
    """
    path = Path(path)
    kind = format if format is not None else path.suffix.lower().lstrip(".")
    writers: dict[str, Callable[[Path, KeypointSequence], None]] = {
        "trc": write_trc,
        "csv": write_keypoint_csv,
        "npy": write_keypoint_npy,
        "npz": write_keypoint_npz,
        "json": write_keypoint_json,
        "c3d": _write_keypoints_c3d,
    }
    if kind not in writers:
        raise UnsupportedFormatError(
            f"Expected a keypoint output format among {', '.join(KEYPOINT_WRITE_FORMATS)}, "
            f"got {kind or 'no extension'!r} for {path.name!r}"
        )
    writers[kind](path, seq)


def _write_keypoints_c3d(path: Path, seq: KeypointSequence) -> None:
    """A keypoint sequence as a new C3D: residual 0 where present, −1 where missing."""
    if seq.n_dims != 3:
        raise UnsupportedFormatError(
            f"Expected 3D keypoints for a C3D output, got {seq.n_dims}D for {path.name!r}"
        )
    missing = seq.confidence <= 0
    take = MarkerTake(
        points=seq,
        residuals=np.where(missing, -1.0, 0.0),
        camera_masks=np.zeros(missing.shape, dtype=np.intp),
        descriptions=(),
        first_frame=seq.start_frame if seq.start_frame is not None and seq.start_frame > 0 else 1,
        events=(),
        analog_rate=None,
        analog_labels=(),
        reader="",
    )
    write_c3d(path, take)
