"""OpenPose JSON output: one ``*.json`` per frame, or a single file.

Conventions
-----------
* Each file is ``{"people": [{"pose_keypoints_2d": [x0, y0, c0, x1, ...]}, ...]}``; pixels,
  so ``length_unit="px"`` and ``n_dims=2`` (Z is 0).
* A folder's files are ordered by the last run of digits in their names (``cam01.0012.json``
  → 12, ``video_000000000012_keypoints.json`` → 12), then by name. Those numbers are the frame
  numbers: where they skip (``…000``–``…003``, ``…009``), the frames in between are missing
  (all NaN), recorded in ``assumptions``. Without a number in every name, with a number
  repeated, or with gaps spanning more than 4× the files, the files are consecutive frames.
* ``person_index`` picks one entry of ``people`` (default 0). A frame where that person is
  absent is all missing.
* A keypoint with confidence 0 (OpenPose writes ``0,0,0`` for undetected points) is missing:
  NaN positions and confidence 0. Nothing is zero-filled.
* Names: 25 keypoints are BODY_25B (Pose2Sim's model) unless their geometry says BODY_25
  (``layout="auto"``: in BODY_25, Neck is the mid-shoulder point and MidHip the mid-hip point);
  18 are COCO-18; other counts get generic names. The choice made by ``"auto"`` is recorded in
  ``assumptions``.
* The files carry no frame rate: ``fps`` is a parameter (default 30, recorded as an assumption).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.keypoint_input import (
    build_keypoint_sequence,
    parse_json,
    read_file_bytes,
    resolve_fps,
)
from mocapqa.io.keypoint_layouts import (
    BODY_25_NAMES,
    BODY_25B_NAMES,
    COCO_18_NAMES,
    generic_names,
)

__all__ = [
    "OPENPOSE_DEFAULT_FPS",
    "OPENPOSE_LAYOUTS",
    "openpose_frame_files",
    "parse_openpose_frame",
    "read_openpose",
]

# Frame rate assumed (and recorded) when the caller gives none: OpenPose JSON stores none.
OPENPOSE_DEFAULT_FPS = 30.0
# Keypoint layouts the reader knows; "auto" chooses by count and geometry.
OPENPOSE_LAYOUTS = ("auto", "BODY_25B", "BODY_25", "COCO_18")
_DIGITS = re.compile(r"\d+")
_MIDPOINT_TOLERANCE = 0.15


def _frame_key(path: Path) -> tuple[int, str]:
    runs = _DIGITS.findall(path.stem)
    return (int(runs[-1]) if runs else -1, path.name)


_MAX_GAP_FACTOR = 4


def _frame_slots(files: list[Path], notes: list[str]) -> tuple[list[int], int | None]:
    """Frame index of each file (in order) and the first frame number, if the names give them.

    The index is the file's frame number less the first one, or its position in the folder.
    """
    numbers = [_frame_key(f)[0] for f in files]
    consecutive = list(range(len(files)))
    if min(numbers) < 0 or len(set(numbers)) != len(numbers):
        return consecutive, None
    slots = [n - numbers[0] for n in numbers]
    span = slots[-1] + 1
    if span == len(files):
        return slots, numbers[0]
    if span > _MAX_GAP_FACTOR * len(files):
        notes.append(
            f"frame numbers span {span} frames for {len(files)} files: read as consecutive frames"
        )
        return consecutive, None
    notes.append(
        f"frame numbers {numbers[0]}–{numbers[-1]} skip {span - len(files)} frame(s): "
        "those frames are missing"
    )
    return slots, numbers[0]


def openpose_frame_files(folder: str | Path) -> list[Path]:
    """The ``*.json`` files of an OpenPose output folder in frame order.

    Parameters
    ----------
    folder : str or Path
        The folder.

    Returns
    -------
    list of Path
        Files sorted by the frame number in their names.

    Raises
    ------
    ParseError
        When the folder holds no JSON file.
    """
    files = sorted((p for p in Path(folder).glob("*.json") if p.is_file()), key=_frame_key)
    if not files:
        raise ParseError("Expected OpenPose *.json files in the folder, got none", folder)
    return files


def parse_openpose_frame(
    data: bytes | str, path: str | Path = "<openpose>", person_index: int = 0
) -> FloatArray | None:
    """Parse one OpenPose JSON frame and return one person's keypoints.

    Parameters
    ----------
    data, path : bytes or str, str or Path
        The file's content, and its name in messages.
    person_index : int
        Which entry of ``people`` to return.

    Returns
    -------
    ndarray, shape (K, 3), or None
        Rows ``(x, y, confidence)`` as written; None when the person is absent.

    Raises
    ------
    ParseError
        On invalid JSON (with its line) or a wrong structure (with the field).
    """
    document: Any = parse_json(data, path)
    if not isinstance(document, dict) or not isinstance(document.get("people"), list):
        raise ParseError("Expected an object with a 'people' list", path, field="people")
    people: list[Any] = document["people"]
    if person_index >= len(people):
        return None
    field = f"people[{person_index}].pose_keypoints_2d"
    person = people[person_index]
    values = person.get("pose_keypoints_2d") if isinstance(person, dict) else None
    if not isinstance(values, list) or len(values) % 3 or not values:
        raise ParseError("Expected a non-empty list of x, y, c triples", path, field=field)
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        raise ParseError("Expected numbers only", path, field=field)
    triples = np.asarray(values, dtype=np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(triples)):
        raise ParseError("Expected finite numbers, got NaN or infinity", path, field=field)
    if np.any((triples[:, 2] < 0) | (triples[:, 2] > 1)):
        raise ParseError("Expected confidence in [0, 1]", path, field=field)
    return triples


def _midpoint_residual(xy: FloatArray, middle: int, a: int, b: int) -> float:
    span = np.linalg.norm(xy[:, a] - xy[:, b], axis=-1)
    off = np.linalg.norm(xy[:, middle] - 0.5 * (xy[:, a] + xy[:, b]), axis=-1)
    ratio = off[span > 0] / span[span > 0]
    ratio = ratio[np.isfinite(ratio)]
    return float(np.median(ratio)) if ratio.size else math.inf


def _names(xy: FloatArray, layout: str, path: str | Path, notes: list[str]) -> tuple[str, ...]:
    n = xy.shape[1]
    if layout == "BODY_25B" or layout == "BODY_25":
        if n != 25:
            raise ParseError(f"Expected 25 keypoints for {layout}, got {n}", path, field="layout")
        return BODY_25B_NAMES if layout == "BODY_25B" else BODY_25_NAMES
    if layout == "COCO_18":
        if n != 18:
            raise ParseError(f"Expected 18 keypoints for COCO_18, got {n}", path, field="layout")
        return COCO_18_NAMES
    if n == 18:
        return COCO_18_NAMES
    if n != 25:
        notes.append(f"keypoint names unknown for {n} OpenPose keypoints: generic names used")
        return generic_names(n)
    neck = _midpoint_residual(xy, 1, 2, 5)
    mid_hip = _midpoint_residual(xy, 8, 9, 12)
    if neck < _MIDPOINT_TOLERANCE and mid_hip < _MIDPOINT_TOLERANCE:
        notes.append("layout BODY_25 inferred: Neck and MidHip lie midway between their pairs")
        return BODY_25_NAMES
    notes.append("layout BODY_25B assumed for 25 OpenPose keypoints")
    return BODY_25B_NAMES


def read_openpose(
    path: str | Path,
    fps: float | None = None,
    person_index: int = 0,
    layout: str = "auto",
) -> KeypointSequence:
    """Read OpenPose JSON output: a folder of per-frame files or a single file.

    Parameters
    ----------
    path : str or Path
        A folder of ``*.json`` frames, or one JSON file (one frame).
    fps : float, optional
        Frames per second; the files do not store it. Default 30, recorded in ``assumptions``.
    person_index : int
        Which entry of ``people`` to read in every frame (default 0).
    layout : {"auto", "BODY_25B", "BODY_25", "COCO_18"}
        Keypoint naming; see the module notes for ``"auto"``.

    Returns
    -------
    KeypointSequence
        Positions ``(F, K, 3)`` in pixels with Z = 0, ``n_dims=2``, OpenPose confidence.

    Raises
    ------
    ParseError
        On unreadable or malformed files, a keypoint count that changes between frames, or when
        the person is absent from every frame.
    """
    if layout not in OPENPOSE_LAYOUTS:
        raise ParseError(f"Expected layout in {OPENPOSE_LAYOUTS}, got {layout!r}", path)
    if person_index < 0:
        raise ParseError(f"Expected person_index >= 0, got {person_index}", path)
    files = openpose_frame_files(path) if Path(path).is_dir() else [Path(path)]
    notes: list[str] = []
    slots, first_number = _frame_slots(files, notes)
    frames: list[FloatArray | None] = []
    n_keypoints: int | None = None
    for file in files:
        triples = parse_openpose_frame(read_file_bytes(file), file, person_index)
        if triples is not None:
            if n_keypoints is not None and len(triples) != n_keypoints:
                raise ParseError(
                    f"Expected {n_keypoints} keypoints as in earlier frames, got {len(triples)}",
                    file,
                    field=f"people[{person_index}].pose_keypoints_2d",
                )
            n_keypoints = len(triples)
        frames.append(triples)
    if n_keypoints is None:
        raise ParseError(f"Expected person {person_index} in at least one frame, got none", path)
    n_frames = int(slots[-1]) + 1
    positions = np.full((n_frames, n_keypoints, 3), np.nan)
    confidence = np.zeros((n_frames, n_keypoints))
    for i, triples in zip(slots, frames, strict=True):
        if triples is None:
            continue
        found = triples[:, 2] > 0
        positions[i, found, :2] = triples[found, :2]
        positions[i, found, 2] = 0.0
        confidence[i, found] = triples[found, 2]
    names = _names(positions[..., :2], layout, path, notes)
    rate = resolve_fps(fps, None, OPENPOSE_DEFAULT_FPS, path, "OpenPose JSON", notes)
    return build_keypoint_sequence(
        path,
        names,
        positions,
        confidence,
        rate,
        length_unit="px",
        n_dims=2,
        source_format="openpose",
        assumptions=notes,
        frame_numbers=None if first_number is None else first_number + np.arange(n_frames),
    )
