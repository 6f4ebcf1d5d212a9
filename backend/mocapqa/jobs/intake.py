"""Receiving a take: stream to disk with a size limit, read and check it, store, queue its run.

The take is read and checked by the one function every intake path shares
(:func:`mocapqa.jobs.take_reading.read_checked_take`). Nothing is stored when any step fails:
the partial file is removed and no row is written.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from mocapqa.errors import InputError, ParseError, TooLargeError
from mocapqa.jobs.reading_record import write_reading
from mocapqa.jobs.runner import JobRunner
from mocapqa.jobs.take_reading import (
    CheckedTake,
    name_too_long,
    read_checked_take,
    safe_file_name,
)
from mocapqa.pipeline.loading import ReadLimits, ReadOptions
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository
from mocapqa.store.stamps import new_id

__all__ = ["CHUNK_BYTES", "Received", "ingest_take", "receive"]

CHUNK_BYTES = 1 << 20
"""Bytes read from an upload at a time while streaming it to disk."""


@dataclass(frozen=True)
class Received:
    """An upload streamed to disk: its size in bytes and SHA-256."""

    size: int
    sha256: str


def receive(source: BinaryIO, target: Path, name: str, max_bytes: int) -> Received:
    """Stream ``source`` to ``target`` in :data:`CHUNK_BYTES` chunks, hashing it.

    Raises
    ------
    TooLargeError
        Past ``max_bytes`` (naming ``name``); ``target`` keeps what was written.
    """
    digest = hashlib.sha256()
    size = 0
    with target.open("wb") as out:
        while chunk := source.read(CHUNK_BYTES):
            size += len(chunk)
            if size > max_bytes:
                raise TooLargeError(
                    f"Expected an upload of at most {max_bytes} bytes, got more ({name!r})"
                )
            digest.update(chunk)
            out.write(chunk)
    return Received(size, digest.hexdigest())


@dataclass(frozen=True)
class _Owner:
    """Whom a new take belongs to: its shoot and its uploader."""

    shoot_id: str | None
    owner_id: int | None


def _store(
    incoming: Path,
    checked: CheckedTake,
    received: Received,
    owner: _Owner,
    read: ReadOptions | None,
    options: AnalysisOptions | None,
    repository: Repository,
    files: FileStore,
) -> tuple[str, str]:
    """Move the checked take into its folder with its reading record, and write its row and
    its first (queued) run; the folder is removed again when the rows cannot be written."""
    take_id = new_id()
    files.adopt(incoming, take_id, checked.file_name)
    write_reading(files, take_id, checked.facts(read))
    values = {
        **checked.row(),
        "id": take_id,
        "size_bytes": received.size,
        "sha256": received.sha256,
        "shoot_id": owner.shoot_id,
        "owner_id": owner.owner_id,
    }
    try:
        _, run_id = repository.add_take(values, (options or AnalysisOptions()).to_json())
    except Exception:
        files.remove_take(take_id, [])
        raise
    return take_id, run_id


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
        ``InputError`` too for a name over :data:`~mocapqa.jobs.take_reading.MAX_NAME_CHARS`.
    """
    too_long = name_too_long(name)
    if too_long is not None:
        raise InputError(too_long)
    file_name = safe_file_name(name)
    incoming = files.incoming_path(Path(file_name).suffix.lower())
    try:
        received = receive(source, incoming, name, max_bytes)
        if received.size == 0:
            raise ParseError("Expected a non-empty file, got 0 bytes", file_name)
        checked = read_checked_take(incoming, name, read, limits)
        owner = _Owner(shoot_id, owner_id)
        take_id, run_id = _store(
            incoming, checked, received, owner, read, options, repository, files
        )
    finally:
        incoming.unlink(missing_ok=True)
    runner.submit(run_id, checked.take, client)
    return take_id, run_id
