"""Reading a take to store it: its name checked, the file read and checked, its row described.

One function, :func:`read_checked_take`, serves every way a take comes in: an upload
(:mod:`mocapqa.jobs.intake`), a shoot import (each file or archive member through the upload)
and a batch (:mod:`mocapqa.jobs.take_task`), so each refuses the same files with the same
errors and describes a take the same way.

Conventions
-----------
* A file name longer than :data:`MAX_NAME_CHARS` is refused (no file system makes one), not
  cut; the stored name is :func:`safe_file_name`'s, the name shown is :func:`take_name`'s.
* A reader tripping over bytes it did not foresee (a ``ValueError`` deep in a parser, a
  ``RecursionError`` on deeply nested JSON, ...) raises a :class:`ParseError` naming the file:
  it is still the input's fault.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mocapqa.core.motion import Motion
from mocapqa.core.text import display_name
from mocapqa.errors import InputError, MocapQAError, ParseError
from mocapqa.io.formats import require_frames
from mocapqa.pipeline.loading import (
    ReadLimits,
    ReadOptions,
    Take,
    detect_take_format,
    read_take_file,
    reading_facts,
)

__all__ = [
    "MAX_NAME_CHARS",
    "CheckedTake",
    "name_too_long",
    "read_checked_take",
    "safe_file_name",
    "take_name",
]

MAX_NAME_CHARS = 255
"""Longest file name of a take, in characters: what file systems keep (255 bytes on Linux,
255 UTF-16 units on Windows and macOS), and the size of the take name column. A longer name
comes from no file system: it is refused, not cut."""

UNFORESEEN = (ValueError, LookupError, TypeError, OverflowError, EOFError, OSError, RecursionError)
"""What a reader may raise on bytes it did not foresee (turned into a :class:`ParseError`)."""


def name_too_long(name: str) -> str | None:
    """Why a take's file name is refused (an "Expected …, got …" message), or None."""
    if len(name) <= MAX_NAME_CHARS:
        return None
    return f"Expected a file name of at most {MAX_NAME_CHARS} characters, got {len(name)}"


def safe_file_name(name: str) -> str:
    """A file name safe to store: the base name, with unusual characters replaced, at most
    200 characters, its extension kept (readers and downloads go by it)."""
    base = Path(name.replace("\\", "/")).name.strip() or "take"
    cleaned = re.sub(r"[^A-Za-z0-9._-]+", "_", base).lstrip(".")
    suffix = Path(cleaned).suffix[:20]
    if len(cleaned) > 200:
        cleaned = cleaned[: 200 - len(suffix)] + suffix
    return cleaned or "take"


def take_name(name: str) -> str:
    """The name a take is shown by: the base of the client's file name without control and
    format characters (:func:`~mocapqa.core.text.display_name`), else the stored name."""
    return display_name(Path(name.replace("\\", "/")).name) or safe_file_name(name)


@dataclass(frozen=True)
class CheckedTake:
    """A take read and checked, with what its row records.

    Attributes
    ----------
    take : Motion or KeypointSequence
        The take as read.
    format_name : str
        Its format (``"bvh"``, ``"trc"``, ...).
    file_name : str
        The name it is stored under (:func:`safe_file_name`).
    name : str
        The name it is shown by (:func:`take_name`).
    """

    take: Take
    format_name: str
    file_name: str
    name: str

    def row(self) -> dict[str, Any]:
        """The take row's values the file decides: ``name``, ``format``, ``kind``,
        ``n_frames``, ``fps``, ``n_joints`` (joints or points) and ``file_name``."""
        take = self.take
        if isinstance(take, Motion):
            kind, n_points = "motion", take.skeleton.n_joints
        else:
            kind, n_points = "keypoints", take.n_keypoints
        return {
            "name": self.name,
            "format": self.format_name,
            "kind": kind,
            "n_frames": take.n_frames,
            "fps": take.fps,
            "n_joints": n_points,
            "file_name": self.file_name,
        }

    def facts(self, read: ReadOptions | None = None) -> dict[str, Any]:
        """How the take was read (:func:`~mocapqa.pipeline.loading.reading_facts`)."""
        return reading_facts(self.take, read or ReadOptions())


def read_checked_take(
    path: Path,
    name: str,
    read: ReadOptions | None = None,
    limits: ReadLimits | None = None,
    label: str | None = None,
) -> CheckedTake:
    """Read a take file (or OpenPose frame folder) and check it can be analysed.

    Parameters
    ----------
    path : Path
        Where the take is (an upload's temporary file, a batch's own file).
    name : str
        The name the client gave it (a file name, possibly with folders).
    read : ReadOptions, optional
        How to read what the file leaves open (defaults when None).
    limits : ReadLimits, optional
        Take size limits (none when None).
    label : str, optional
        How errors name the file (its stored name when None).

    Returns
    -------
    CheckedTake

    Raises
    ------
    InputError
        For a name over :data:`MAX_NAME_CHARS`.
    FormatError, ParseError, TooLargeError
        For a file no reader takes, malformed or unforeseen content (naming the file), a
        take without frames, or one over ``limits``.
    """
    too_long = name_too_long(name)
    if too_long is not None:
        raise InputError(too_long)
    file_name = safe_file_name(name)
    label = label or file_name
    format_name = detect_take_format(path, label)
    try:
        take = read_take_file(path, format_name, label, read, limits)
    except MocapQAError:
        raise
    except UNFORESEEN as e:
        # A reader tripping over bytes it did not foresee is still the input's fault.
        raise ParseError(
            f"Expected a readable {format_name} file, got {type(e).__name__}: {e}", label
        ) from e
    require_frames(take, label)
    return CheckedTake(take, format_name, file_name, take_name(name))
