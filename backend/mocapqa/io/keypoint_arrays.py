"""Keypoint arrays in NumPy files: ``.npy`` and ``.npz``.

Conventions
-----------
* ``.npy`` holds ``(F, K, 3)`` positions or ``(F, K, 4)`` with confidence as the 4th column
  (``(F, K, 2)`` is read as 2D). Names are generic (``keypoint_0`` ...); fps and unit are not
  stored, so ``fps`` is required and the unit is "unknown" unless ``length_unit`` is given.
* ``.npz`` holds ``positions`` (or ``keypoints``) as above and may carry ``confidence``
  ``(F, K)``, ``names`` ``(K,)``, ``fps``, ``unit`` and ``n_dims``; the writer stores all of them.
* Arrays are loaded with ``allow_pickle=False``. NaN is missing; infinity is an error.
* Every array header is read first (:func:`mocapqa.io.guards.read_npy_header`): an array of
  Python objects is refused, and so is a header declaring more data than the file (or the
  ``.npz`` member) holds, before NumPy allocates what the header declares.
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.atomic import atomic_path
from mocapqa.io.guards import ZIP_READ_ERRORS, read_npy_header
from mocapqa.io.keypoint_input import (
    build_keypoint_sequence,
    read_file_bytes,
    resolve_fps,
    resolve_length_unit,
)
from mocapqa.io.keypoint_layouts import generic_names

__all__ = [
    "parse_keypoint_npy",
    "parse_keypoint_npz",
    "read_keypoint_npy",
    "read_keypoint_npz",
    "write_keypoint_npy",
    "write_keypoint_npz",
]


def _split(
    array: NDArray[Any], path: str, field: str
) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, int]:
    if not isinstance(array, np.ndarray):  # an .npz member without the .npy format
        raise ParseError("Expected a NumPy array, got other data", path, field=field)
    if array.ndim != 3 or array.shape[2] not in (2, 3, 4):
        raise ParseError(
            f"Expected an array of shape (F, K, 2|3|4), got {array.shape}", path, field=field
        )
    # Real numbers only: a complex array would lose its imaginary part in the cast, a boolean
    # one read as 0/1 coordinates.
    if array.dtype.kind not in "iuf":
        raise ParseError(
            f"Expected an array of real numbers, got dtype {array.dtype}", path, field=field
        )
    try:
        values = np.asarray(array, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ParseError(f"Expected numbers, got dtype {array.dtype}", path, field=field) from e
    if np.any(np.isinf(values)):
        raise ParseError("Expected finite values or NaN, got infinity", path, field=field)
    n_dims = 2 if values.shape[2] == 2 else 3
    positions = np.zeros((*values.shape[:2], 3))
    positions[..., :n_dims] = values[..., :n_dims]
    positions[np.any(np.isnan(values[..., :n_dims]), axis=-1)] = np.nan
    confidence = values[..., 3] if values.shape[2] == 4 else None
    return positions, confidence, n_dims


def _check_declared(declared: int, held: int, path: str, member: str | None = None) -> None:
    if declared > held:
        raise ParseError(
            f"Expected at most the {held} bytes of data the file holds, got a header "
            f"declaring {declared} (a truncated file, or a header that lies)",
            path,
            field=member,
        )


def _check_headers(data: bytes, path: str) -> None:
    """Read every array header of ``.npy`` or ``.npz`` bytes before NumPy loads them."""
    if data.startswith(b"\x93NUMPY"):
        handle = io.BytesIO(data)
        header = read_npy_header(handle, path)
        _check_declared(header.n_bytes, len(data) - header.offset, path)
        return
    if not data.startswith(b"PK"):
        raise ParseError(
            "Expected a NumPy file (a .npy starting with \\x93NUMPY, or an .npz zip archive), "
            "got other data",
            path,
        )
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            for member in archive.infolist():
                if member.filename.endswith(".npy"):
                    with archive.open(member) as stream:
                        header = read_npy_header(stream, path)
                    key = member.filename.removesuffix(".npy")
                    _check_declared(header.n_bytes, member.file_size - header.offset, path, key)
    except ZIP_READ_ERRORS as e:
        raise ParseError(f"Expected a readable .npz archive, got {e}", path) from e


_LOAD_ERRORS: tuple[type[Exception], ...] = (*ZIP_READ_ERRORS, KeyError)
"""What NumPy's loading of a damaged ``.npy``/``.npz`` raises."""
_NPZ_READ_ERRORS: tuple[type[Exception], ...] = (*ZIP_READ_ERRORS, TypeError)
"""What reading an ``.npz`` archive's arrays raises on damaged members or wrong types."""


def _load(data: bytes, path: str) -> Any:
    _check_headers(data, path)
    try:
        return np.load(io.BytesIO(data), allow_pickle=False)
    except _LOAD_ERRORS as e:
        raise ParseError(f"Expected a NumPy file, got unreadable data ({e})", path) from e


def parse_keypoint_npy(
    data: bytes,
    path: str | Path = "<keypoints.npy>",
    fps: float | None = None,
    length_unit: str | None = None,
) -> KeypointSequence:
    """Parse ``.npy`` bytes holding ``(F, K, 3|4)`` keypoints.

    Parameters
    ----------
    data, path : bytes, str or Path
        The file's content, and its name in messages.
    fps : float
        Frames per second (required: the file does not store it).
    length_unit : str, optional
        Unit of the coordinates; "unknown" when not given.

    Returns
    -------
    KeypointSequence
        Positions ``(F, K, 3)``; confidence from the 4th column or 1.0.

    Raises
    ------
    ParseError
        On an unreadable file, a wrong shape or dtype, infinity, or a missing ``fps``.
    """
    path = str(path)
    array = _load(data, path)
    if not isinstance(array, np.ndarray):
        raise ParseError("Expected a .npy array, got an .npz archive", path)
    positions, confidence, n_dims = _split(array, path, "array")
    notes: list[str] = []
    rate = resolve_fps(fps, None, None, path, "NPY", notes)
    unit = resolve_length_unit(length_unit, "unknown", path, notes)
    conf = np.ones(positions.shape[:2]) if confidence is None else confidence
    return build_keypoint_sequence(
        path, generic_names(positions.shape[1]), positions, conf, rate,
        length_unit=unit, n_dims=n_dims, source_format="npy", assumptions=notes,
    )  # fmt: skip


def _scalar(archive: Any, key: str, path: str) -> Any:
    value = archive[key]
    if not isinstance(value, np.ndarray):
        raise ParseError("Expected a NumPy scalar, got other data", path, field=key)
    if value.ndim != 0:
        raise ParseError(f"Expected a scalar, got shape {value.shape}", path, field=key)
    return value.item()


def parse_keypoint_npz(
    data: bytes,
    path: str | Path = "<keypoints.npz>",
    fps: float | None = None,
    length_unit: str | None = None,
) -> KeypointSequence:
    """Parse ``.npz`` bytes (see the module notes for the keys).

    Parameters
    ----------
    data, path : bytes, str or Path
        The file's content, and its name in messages.
    fps : float, optional
        Frames per second; else the archive's ``fps``; else an error.
    length_unit : str, optional
        Unit; else the archive's ``unit``; else "unknown".

    Returns
    -------
    KeypointSequence
        The sequence.

    Raises
    ------
    ParseError
        On an unreadable archive or a wrong key, naming the field.
    """
    path = str(path)
    archive = _load(data, path)
    if not hasattr(archive, "files"):
        raise ParseError("Expected an .npz archive, got a .npy array", path)
    try:
        with archive:
            key = "positions" if "positions" in archive.files else "keypoints"
            if key not in archive.files:
                if not path.lower().endswith(".npz"):
                    # An .npz is a zip file: a .zip of takes lands here when sent as one take.
                    raise ParseError(
                        "Expected one take, got a zip archive: import archives of takes into a "
                        "shoot (POST /shoots/{id}/takes, or the shoot view)",
                        path,
                    )
                raise ParseError("Expected a 'positions' array", path, field="positions")
            positions, confidence, n_dims = _split(archive[key], path, key)
            if "confidence" in archive.files:
                confidence = np.asarray(archive["confidence"], dtype=np.float64)
            names = generic_names(positions.shape[1])
            if "names" in archive.files:
                names = tuple(str(n) for n in np.asarray(archive["names"]).ravel())
            file_fps = float(_scalar(archive, "fps", path)) if "fps" in archive.files else None
            unit = str(_scalar(archive, "unit", path)) if "unit" in archive.files else None
            if "n_dims" in archive.files:
                n_dims = int(_scalar(archive, "n_dims", path))
    except _NPZ_READ_ERRORS as e:
        raise ParseError(f"Expected a readable .npz archive, got {e}", path) from e
    if len(names) != positions.shape[1]:
        raise ParseError(
            f"Expected {positions.shape[1]} names, got {len(names)}", path, field="names"
        )
    notes: list[str] = []
    rate = resolve_fps(fps, file_fps, None, path, "NPZ", notes)
    unit = resolve_length_unit(length_unit or unit, "unknown", path, notes)
    conf = np.ones(positions.shape[:2]) if confidence is None else confidence
    if conf.shape != positions.shape[:2] or np.any(np.isinf(conf)):
        raise ParseError(
            f"Expected finite confidence of shape {positions.shape[:2]}", path, field="confidence"
        )
    return build_keypoint_sequence(
        path, names, positions, np.nan_to_num(conf), rate,
        length_unit=unit, n_dims=n_dims, source_format="npz", assumptions=notes,
    )  # fmt: skip


def read_keypoint_npy(
    path: str | Path, fps: float | None = None, length_unit: str | None = None
) -> KeypointSequence:
    """Read a ``.npy`` keypoint file. See :func:`parse_keypoint_npy`."""
    return parse_keypoint_npy(read_file_bytes(path), path, fps, length_unit)


def read_keypoint_npz(
    path: str | Path, fps: float | None = None, length_unit: str | None = None
) -> KeypointSequence:
    """Read a ``.npz`` keypoint file. See :func:`parse_keypoint_npz`."""
    return parse_keypoint_npz(read_file_bytes(path), path, fps, length_unit)


def write_keypoint_npy(path: str | Path, seq: KeypointSequence) -> None:
    """Write ``(F, K, 4)`` positions plus confidence to ``.npy`` (names, fps and unit are lost).

    Parameters
    ----------
    path, seq : str or Path, KeypointSequence
        The destination file, and the data.
    """
    stacked = np.concatenate([seq.positions, seq.confidence[..., None]], axis=-1)
    with atomic_path(path) as temporary, temporary.open("wb") as handle:
        np.save(handle, stacked, allow_pickle=False)


def write_keypoint_npz(path: str | Path, seq: KeypointSequence) -> None:
    """Write a sequence to ``.npz`` with every field needed to read it back unchanged.

    Parameters
    ----------
    path, seq : str or Path, KeypointSequence
        The destination file, and the data.
    """
    with atomic_path(path) as temporary, temporary.open("wb") as handle:
        np.savez(
            handle,
            positions=seq.positions,
            confidence=seq.confidence,
            names=np.array(seq.names, dtype=str),
            fps=np.float64(seq.fps),
            unit=np.str_(seq.length_unit),
            n_dims=np.int64(seq.n_dims),
        )
