"""Receiving a take: stream to disk with a size limit, detect, parse, store, queue its first run.

Nothing is stored when any step fails: the partial file is removed and no row is written.
"""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path
from typing import Any, BinaryIO

from mocapqa.core.motion import Motion
from mocapqa.core.text import display_name
from mocapqa.errors import InputError, MocapQAError, ParseError, TooLargeError
from mocapqa.io.formats import require_frames
from mocapqa.jobs.runner import JobRunner
from mocapqa.pipeline.loading import (
    READING_FILE,
    ReadLimits,
    ReadOptions,
    detect_take_format,
    read_take_file,
    reading_facts,
)
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository, new_id

__all__ = [
    "CHUNK_BYTES",
    "MAX_NAME_CHARS",
    "ingest_take",
    "joint_parents_of",
    "joints_of",
    "name_too_long",
    "reading_of",
    "safe_file_name",
]

CHUNK_BYTES = 1 << 20
"""Bytes read from an upload at a time while streaming it to disk."""
MAX_NAME_CHARS = 255
"""Longest file name of a take, in characters: what file systems keep (255 bytes on Linux,
255 UTF-16 units on Windows and macOS), and the size of the take name column. A longer name
comes from no file system: it is refused, not cut."""


def name_too_long(name: str) -> str | None:
    """Why a take's file name is refused (an "Expected …, got …" message), or None."""
    if len(name) <= MAX_NAME_CHARS:
        return None
    return f"Expected a file name of at most {MAX_NAME_CHARS} characters, got {len(name)}"


def reading_of(files: FileStore, take_id: str) -> dict[str, Any] | None:
    """How a take was read (:func:`~mocapqa.pipeline.loading.reading_facts`), if recorded."""
    path = files.take_dir(take_id) / READING_FILE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


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


def safe_file_name(name: str) -> str:
    """A file name safe to store: the base name, with unusual characters replaced, at most
    200 characters, its extension kept (readers and downloads go by it)."""
    base = Path(name.replace("\\", "/")).name.strip() or "take"
    cleaned = re.sub(r"[^A-Za-z0-9._-]+", "_", base).lstrip(".")
    suffix = Path(cleaned).suffix[:20]
    if len(cleaned) > 200:
        cleaned = cleaned[: 200 - len(suffix)] + suffix
    return cleaned or "take"


def ingest_take(
    source: BinaryIO,
    name: str,
    repository: Repository,
    files: FileStore,
    runner: JobRunner,
    max_bytes: int,
    options: AnalysisOptions | None = None,
    read: ReadOptions | None = None,
    limits: ReadLimits | None = None,
    client: str = "local",
    shoot_id: str | None = None,
    owner_id: int | None = None,
) -> tuple[str, str]:
    """Store an uploaded take and queue its analysis.

    Parameters
    ----------
    source : binary file
        The upload, read in chunks.
    name : str
        The client's file name.
    max_bytes : int
        Largest accepted size, bytes.
    options : AnalysisOptions, optional
        Options of the first run (defaults when None).
    read : ReadOptions, optional
        How to read what the file leaves open (frame rate, unit, BVH root position); kept
        with the take, with what the reader used or assumed, for every later run.
    limits : ReadLimits, optional
        Take size limits, checked before parsing where the bytes tell (none when None).
    client : str
        Who uploads (for the runner's fair queue).
    shoot_id : str, optional
        Shoot the take joins.
    owner_id : int, optional
        The uploading user, stored with the take's row (none on a server without users), so
        no take is ever stored without its owner.

    Returns
    -------
    take_id, run_id : str

    Raises
    ------
    TooLargeError, FormatError, ParseError, InputError
        ``InputError`` too for a name over :data:`MAX_NAME_CHARS`.
    """
    too_long = name_too_long(name)
    if too_long is not None:
        raise InputError(too_long)
    file_name = safe_file_name(name)
    incoming = files.incoming_path(Path(file_name).suffix.lower())
    digest = hashlib.sha256()
    size = 0
    try:
        with incoming.open("wb") as out:
            while chunk := source.read(CHUNK_BYTES):
                size += len(chunk)
                if size > max_bytes:
                    raise TooLargeError(
                        f"Expected an upload of at most {max_bytes} bytes, got more ({name!r})"
                    )
                digest.update(chunk)
                out.write(chunk)
        if size == 0:
            raise ParseError("Expected a non-empty file, got 0 bytes", file_name)
        format_name = detect_take_format(incoming, file_name)
        try:
            take = read_take_file(incoming, format_name, file_name, read, limits)
        except MocapQAError:
            raise
        except (
            ValueError,
            LookupError,
            TypeError,
            OverflowError,
            EOFError,
            OSError,
            RecursionError,
        ) as e:
            # A reader tripping over bytes it did not foresee is still the input's fault.
            raise ParseError(
                f"Expected a readable {format_name} file, got {type(e).__name__}: {e}", file_name
            ) from e
        require_frames(take, file_name)
        if isinstance(take, Motion):
            kind, n_points, fps = "motion", take.skeleton.n_joints, take.fps
        else:
            kind, n_points, fps = "keypoints", take.n_keypoints, take.fps
        take_id = new_id()
        files.adopt(incoming, take_id, file_name)
        facts = reading_facts(take, read or ReadOptions())
        files.write_bytes(files.take_dir(take_id) / READING_FILE, json.dumps(facts).encode())
        try:
            _, run_id = repository.add_take(
                {
                    "id": take_id,
                    "name": display_name(Path(name.replace("\\", "/")).name) or file_name,
                    "format": format_name,
                    "kind": kind,
                    "size_bytes": size,
                    "sha256": digest.hexdigest(),
                    "n_frames": take.n_frames,
                    "fps": fps,
                    "n_joints": n_points,
                    "file_name": file_name,
                    "shoot_id": shoot_id,
                    "owner_id": owner_id,
                },
                (options or AnalysisOptions()).to_json(),
            )
        except Exception:
            files.remove_take(take_id, [])
            raise
    finally:
        incoming.unlink(missing_ok=True)
    runner.submit(run_id, take, client)
    return take_id, run_id
