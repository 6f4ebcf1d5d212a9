"""Reading the take a command was given, within the reading limits.

The server refuses a take beyond its limits (``MOCAPQA_MAX_FRAME_POINTS``,
``MOCAPQA_MAX_UNPACKED_MB``, …; docs/io.md) before paying for it. The commands that read a
take a user hands them apply the same limits, from the same settings, so a 1.5 MB ``.npz``
that unpacks to 2,000,000 frames or a multi-gigabyte BVH is refused from its header rather
than read into memory; raise a limit with its environment variable for a take that needs it.
The benches read the corpus without limits.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from mocapqa.errors import InputError

if TYPE_CHECKING:
    from mocapqa.core.keypoints import KeypointSequence
    from mocapqa.core.motion import Motion

__all__ = ["read_input", "read_input_bvh"]


def read_input(path: Path, **options: Any) -> Motion | KeypointSequence:
    """:func:`mocapqa.io.formats.read_take` with the settings' reading limits.

    Raises
    ------
    TooLargeError
        Naming the file and the limit's setting.
    ParseError, UnsupportedFormatError
        As the reader does.
    """
    from mocapqa.config import get_settings
    from mocapqa.io.formats import read_take

    return read_take(path, limits=get_settings().read_limits, **options)


def read_input_bvh(path: Path, **options: Any) -> Motion:
    """:func:`read_input` for a command that works on BVH takes only.

    Raises
    ------
    InputError
        When the file is another format, or does not read as a motion.
    """
    from mocapqa.core.motion import Motion
    from mocapqa.io.formats import detect_format

    kind = detect_format(path)
    if kind != "bvh":
        raise InputError(f"Expected a BVH take, got a {kind} file: {path}")
    take = read_input(path, **options)
    if not isinstance(take, Motion):  # the BVH reader returns a Motion: a broken contract
        raise InputError(
            f"Expected a BVH take to read as a motion, got a {type(take).__name__}: {path}"
        )
    return take
