"""Reading an uploaded take and writing filtered keypoints, by format.

Format detection and reading go through :mod:`mocapqa.io.formats` (BVH and every keypoint
format the I/O layer reads). Parse errors are re-raised with the client's file name in place of
the storage path, keeping the line and field.

How a take is read can be chosen at upload (:class:`ReadOptions`: the frame rate and length
unit of formats that do not store them, and how a BVH root's position is read), and what the
reader used or assumed is described by :func:`reading_facts`, which the API returns with the
take.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from mocapqa.core.keypoints import LENGTH_UNITS, KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError, ParseError, TooLargeError
from mocapqa.io.bvh_root import ROOT_TRANSLATIONS, explain_root_translation
from mocapqa.io.formats import check_fps, detect_format, read_take, write_keypoints
from mocapqa.io.guards import ReadLimits
from mocapqa.kinematics.bindpose import leading_bind_pose

__all__ = [
    "ReadLimits",
    "ReadOptions",
    "Take",
    "detect_take_format",
    "read_take_file",
    "reading_facts",
    "write_keypoints_file",
]

Take = Motion | KeypointSequence
"""What a take file holds: a BVH motion or a keypoint sequence."""


@dataclass(frozen=True, slots=True)
class ReadOptions:
    """How to read a take, where the file leaves it open.

    Parameters
    ----------
    fps : float, optional
        Frames per second for formats that do not store it (OpenPose, MediaPipe, NPY, CSV
        without a time column); the reader's default, recorded as an assumption, when None.
    length_unit : str, optional
        Unit of keypoint coordinates for formats that do not store one.
    root_translation : {"auto", "add", "replace"}
        How a BVH root's position channels combine with its OFFSET.
    """

    fps: float | None = None
    length_unit: str | None = None
    root_translation: Literal["auto", "add", "replace"] = "auto"

    def __post_init__(self) -> None:
        if self.fps is not None:
            check_fps(self.fps)
        if self.length_unit is not None and self.length_unit not in LENGTH_UNITS:
            raise InputError(f"Expected length_unit in {LENGTH_UNITS}, got {self.length_unit!r}")
        if self.root_translation not in ROOT_TRANSLATIONS:
            raise InputError(
                f"Expected root_translation in {ROOT_TRANSLATIONS}, got {self.root_translation!r}"
            )

    def to_json(self) -> dict[str, Any]:
        """The options as a JSON-ready dict."""
        return {
            "fps": self.fps,
            "length_unit": self.length_unit,
            "root_translation": self.root_translation,
        }

    @classmethod
    def from_json(cls, data: dict[str, Any] | None) -> ReadOptions:
        """Options from :meth:`to_json`'s dict (missing fields take their defaults)."""
        data = data or {}
        return cls(
            fps=data.get("fps"),
            length_unit=data.get("length_unit"),
            root_translation=data.get("root_translation") or "auto",
        )


def reading_facts(take: Motion | KeypointSequence, read: ReadOptions) -> dict[str, Any]:
    """What the reader used or assumed for a take, JSON-ready.

    Returns
    -------
    dict
        ``read_options`` (as chosen), ``fps``, ``length_unit`` and, for keypoints,
        ``assumptions`` (frame rate, unit, layout or frame numbers the file did not state);
        for a BVH, ``root_translation``, ``root_translation_reason``, ``bind_pose_frames``
        (:func:`mocapqa.kinematics.bindpose.leading_bind_pose`), ``joints`` and ``joint_parents``
        (the joint names and the hierarchy, by which a run's ``mapping`` option is checked before
        it is queued).
    """
    facts: dict[str, Any] = {"read_options": read.to_json(), "fps": take.fps}
    if isinstance(take, Motion):
        facts["length_unit"] = take.skeleton.length_unit
        facts["root_translation"] = take.skeleton.root_translation
        facts["root_translation_reason"] = explain_root_translation(take, read.root_translation)
        facts["bind_pose_frames"] = leading_bind_pose(take.quats)
        facts["joints"] = list(take.skeleton.names)
        facts["joint_parents"] = [int(p) for p in take.skeleton.parents]
    else:
        facts["length_unit"] = take.length_unit
        facts["source_format"] = take.source_format
        facts["assumptions"] = list(take.assumptions)
    return facts


def detect_take_format(path: Path, display_name: str | None = None) -> str:
    """The format name of a take file (``"bvh"``, ``"trc"``, ``"csv"``, ...), by extension
    or content; ``display_name`` names the file in the error (an upload's own name).

    Raises
    ------
    UnsupportedFormatError
        When no reader recognises the file.
    """
    return detect_format(path, display_name)


def read_take_file(
    path: Path,
    format_name: str,
    display_name: str | None = None,
    read: ReadOptions | None = None,
    limits: ReadLimits | None = None,
) -> Take:
    """Read a take whose format is known.

    Parameters
    ----------
    path : Path
        The file.
    format_name : str
        As returned by :func:`detect_take_format`.
    display_name : str, optional
        Name used in error messages instead of the storage path.
    read : ReadOptions, optional
        How to read what the file leaves open (defaults when None).
    limits : ReadLimits, optional
        Size limits checked before and after the read (the server passes its settings').

    Raises
    ------
    ParseError
        With the file's line when the content is malformed.
    """
    del format_name  # the reader detects it again from the same bytes and name
    read = read or ReadOptions()
    try:
        return read_take(
            path,
            fps=read.fps,
            length_unit=read.length_unit,
            root_translation=read.root_translation,
            limits=limits,
        )
    except ParseError as e:
        raise ParseError(e.message, display_name or path, e.line, e.field) from e
    except TooLargeError as e:
        message = str(e).replace(path.name, display_name or path.name, 1)
        raise TooLargeError(message) from e


def write_keypoints_file(path: Path, sequence: KeypointSequence) -> None:
    """Write keypoints in the format given by the path's suffix (``.csv`` or ``.trc``)."""
    write_keypoints(path, sequence, format=path.suffix.lstrip(".").lower())
