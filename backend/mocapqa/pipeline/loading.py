"""Reading an uploaded take and writing filtered keypoints, by format.

Format detection and reading go through :mod:`mocapqa.io.formats` (BVH and every keypoint
format the I/O layer reads). Parse errors are re-raised with the client's file name in place of
the storage path, keeping the line and field.
"""

from __future__ import annotations

from pathlib import Path

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ParseError
from mocapqa.io.formats import detect_format, read_take, write_keypoints

__all__ = ["Take", "detect_take_format", "read_take_file", "write_keypoints_file"]

Take = Motion | KeypointSequence
"""What a take file holds: a BVH motion or a keypoint sequence."""


def detect_take_format(path: Path) -> str:
    """The format name of a take file (``"bvh"``, ``"trc"``, ``"csv"``, ...), by extension
    or content.

    Raises
    ------
    UnsupportedFormatError
        When no reader recognises the file.
    """
    return detect_format(path)


def read_take_file(path: Path, format_name: str, display_name: str | None = None) -> Take:
    """Read a take whose format is known.

    Parameters
    ----------
    path : Path
        The file.
    format_name : str
        As returned by :func:`detect_take_format`.
    display_name : str, optional
        Name used in error messages instead of the storage path.

    Raises
    ------
    ParseError
        With the file's line when the content is malformed.
    """
    del format_name  # the reader detects it again from the same bytes and name
    try:
        return read_take(path)
    except ParseError as e:
        raise ParseError(e.message, display_name or path, e.line, e.field) from e


def write_keypoints_file(path: Path, sequence: KeypointSequence) -> None:
    """Write keypoints in the format given by the path's suffix (``.csv`` or ``.trc``)."""
    write_keypoints(path, sequence, format=path.suffix.lstrip(".").lower())
