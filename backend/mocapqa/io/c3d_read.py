"""Reading a C3D file: through ezc3d, through py-c3d where ezc3d refuses, or refused.

Conventions
-----------
* The file is checked first (:func:`~mocapqa.io.c3d_layout.inspect_c3d`); ezc3d is given only
  files that pass :func:`~mocapqa.io.c3d_layout.check_for_ezc3d`.
* ezc3d 1.7.2 refuses MIPS (big-endian) files and some non-standard parameters (a FLOAT
  ``ANALOG:OFFSET``); those are read by py-c3d (``c3d`` on PyPI, pure Python), which reads
  both kinds but checks that header and parameters agree. A file neither reads is refused with a
  :class:`~mocapqa.errors.ParseError` giving both reasons.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError, ParseError, UnsupportedFormatError
from mocapqa.io.c3d_layout import C3DLayout, check_for_ezc3d, inspect_c3d
from mocapqa.io.c3d_parameters import C3DParameters, ezc3d_parameters, pyc3d_parameters
from mocapqa.io.c3d_take import MarkerTake, build_marker_take
from mocapqa.io.guards import ReadLimits, check_c3d_header

__all__ = ["read_c3d", "refusal_reason"]


def _from_ezc3d(path: Path, layout: C3DLayout, c3d: Any) -> MarkerTake:
    data = c3d["data"]
    points = data["points"]  # (4, M, F)
    meta = data["meta_points"]
    xyz = np.asarray(points[:3], dtype=np.float64).transpose(2, 1, 0)
    residuals = np.asarray(meta["residuals"][0], dtype=np.float64).T
    masks = np.asarray(meta["camera_masks"], dtype=bool)  # (7, M, F): bit k, camera k + 1
    if masks.size:
        bits = (1 << np.arange(masks.shape[0])).astype(np.uint8)  # at most 127
        camera = np.einsum("k,kmf->fm", bits, masks.view(np.uint8))
    else:
        camera = np.zeros(residuals.shape, dtype=np.uint8)
    first_frame = int(c3d["header"]["points"]["first_frame"]) + 1
    return build_marker_take(
        path,
        xyz,
        residuals,
        camera.astype(np.intp),
        ezc3d_parameters(c3d["parameters"]),
        layout.header.frame_rate,
        first_frame,
        "ezc3d",
    )


def _open_pyc3d(path: Path) -> tuple[int, list[FloatArray], C3DParameters]:
    import c3d as pyc3d

    with path.open("rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reader = pyc3d.Reader(handle)
        first_frame = int(reader.first_frame)
        frames = [points for _, points, _ in reader.read_frames(copy=True)]
        parameters = pyc3d_parameters(reader)
    return first_frame, frames, parameters


def _from_pyc3d(
    path: Path, layout: C3DLayout, first_frame: int, frames: list[FloatArray], parameters: Any
) -> MarkerTake:
    n_points = layout.header.n_points
    block = np.stack(frames) if frames else np.zeros((0, n_points, 5))  # (F, M, 5)
    residuals = block[..., 3].astype(np.float64)
    camera = np.where(residuals < 0, 0, block[..., 4]).astype(np.intp)  # the bits, as stored
    return build_marker_take(
        path,
        block[..., :3].astype(np.float64),
        residuals,
        camera,
        parameters,
        layout.header.frame_rate,
        first_frame,
        "py-c3d",
    )


def refusal_reason(error: BaseException) -> str:
    """Why a reader or writer refused a file: the error's text on one line, at most 200
    characters (its type's name when it has none).

    Parameters
    ----------
    error : BaseException
        What ezc3d or py-c3d raised.

    Returns
    -------
    str
    """
    text = " ".join(str(error).split())[:200]
    return text or type(error).__name__


def read_c3d(path: str | Path, limits: ReadLimits | None = None) -> MarkerTake:
    """Read a C3D file's points, residuals, camera masks, labels, events and analog channels.

    Parameters
    ----------
    path : str or Path
        The file.
    limits : ReadLimits, optional
        Refuse a take whose header declares more frames × points than
        ``limits.max_frame_points``, or more data bytes than ``limits.max_unpacked_bytes``,
        before it is parsed; no limits when None.

    Returns
    -------
    MarkerTake

    Raises
    ------
    ParseError
        On a malformed file (see :func:`~mocapqa.io.c3d_layout.inspect_c3d`), or one that
        neither ezc3d nor py-c3d reads (the message gives both reasons).
    TooLargeError
        When the header declares a take beyond ``limits``.
    """
    path = Path(path)
    layout = inspect_c3d(path)
    if limits is not None:
        check_c3d_header(layout.header, path.name, limits)
    problems = []
    try:
        if layout.header.processor == 86:
            raise UnsupportedFormatError("MIPS processor type not supported")
        check_for_ezc3d(layout, path)
    except InputError as e:
        problems.append(f"ezc3d: {getattr(e, 'message', str(e))}")
    else:
        import ezc3d

        try:
            c3d = ezc3d.c3d(str(path))
        except Exception as e:  # ezc3d raises RuntimeError, ValueError, OSError, IndexError
            problems.append(f"ezc3d: {refusal_reason(e)}")
        else:
            return _from_ezc3d(path, layout, c3d)
    try:
        opened = _open_pyc3d(path)
    except Exception as e:  # py-c3d's consistency checks are assertions
        problems.append(f"py-c3d: {refusal_reason(e)}")
    else:
        return _from_pyc3d(path, layout, *opened)
    raise ParseError(
        "Expected a C3D file that ezc3d or py-c3d reads, got one both refuse "
        f"({'; '.join(problems)})",
        path,
    )
