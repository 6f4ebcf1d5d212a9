"""A take's reading record: how the take was read, kept beside it, written and read here.

The record is ``takes/<take_id>/.reading.json`` (:data:`READING_FILE`): the facts
:func:`~mocapqa.pipeline.loading.reading_facts` gives when the take is read (upload, shoot
import, batch): the read options chosen, the rate and unit used or assumed and, for a BVH take,
its joint names and hierarchy. No other module names the file.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from mocapqa.errors import InputError
from mocapqa.pipeline.loading import ReadOptions
from mocapqa.store.files import FileStore

__all__ = [
    "READING_FILE",
    "joint_parents_of",
    "joints_of",
    "read_options_of",
    "reading_of",
    "write_reading",
]

READING_FILE = ".reading.json"
"""A take's record of how it was read, in its folder (no stored take name starts with ".")."""


def write_reading(files: FileStore, take_id: str, facts: dict[str, Any]) -> None:
    """Record how a take was read (:func:`~mocapqa.pipeline.loading.reading_facts`)."""
    files.write_bytes(files.take_dir(take_id) / READING_FILE, json.dumps(facts).encode())


def reading_in(folder: Path) -> dict[str, Any] | None:
    """How the take in ``folder`` was read, if recorded."""
    try:
        data = json.loads((folder / READING_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def reading_of(files: FileStore, take_id: str) -> dict[str, Any] | None:
    """How a take was read (:func:`~mocapqa.pipeline.loading.reading_facts`), if recorded."""
    return reading_in(files.take_dir(take_id))


def read_options_of(folder: Path) -> ReadOptions:
    """The read options chosen at upload for the take in ``folder``, else the defaults."""
    try:
        return ReadOptions.from_json((reading_in(folder) or {}).get("read_options"))
    except (AttributeError, InputError):
        return ReadOptions()


def joints_of(files: FileStore, take_id: str) -> list[str] | None:
    """A BVH take's joint names as recorded when it was read (None for keypoint takes and
    takes stored before the names were recorded)."""
    joints = (reading_of(files, take_id) or {}).get("joints")
    return [str(j) for j in joints] if isinstance(joints, list) else None


def joint_parents_of(files: FileStore, take_id: str) -> list[int] | None:
    """A BVH take's parent index per joint as recorded when it was read (None for keypoint
    takes and takes stored before the hierarchy was recorded)."""
    parents = (reading_of(files, take_id) or {}).get("joint_parents")
    if not isinstance(parents, list) or not all(
        isinstance(p, int) and not isinstance(p, bool) for p in parents
    ):
        return None
    return [int(p) for p in parents]
