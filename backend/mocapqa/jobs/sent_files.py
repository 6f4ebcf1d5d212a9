"""Files sent to a Dask worker that cannot read the client's disk, and the files it sends back.

A cluster whose workers share the client's storage (the local cluster, a compose stack with
one volume) is sent paths: each worker reads the take and writes the run's outputs into the
data folder itself. A worker on another machine sees neither, so the client sends the take's
bytes (with any limits model the run names from the data folder), the worker analyses them in
a scratch folder of its own, and sends the run's files back for the client to write. Which of
the two a cluster gets is decided by :func:`workers_share`, asked once per batch (or per
server run) of every connected worker.

Conventions
-----------
* A :class:`SentFiles` holds relative POSIX paths and their bytes; unpacking refuses an
  absolute path or one that climbs out (``..``), so a worker (or a client, for what comes
  back) cannot be made to write outside its folder.
* Nothing here imports the analysis stack: the batch client uses it too.
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any

from mocapqa.errors import InputError

__all__ = ["SentFiles", "pack", "pack_tree", "probe_token", "sees", "workers_share"]


@dataclass(frozen=True)
class SentFiles:
    """Files by relative POSIX path, to be written under another folder.

    Parameters
    ----------
    files : tuple of (str, bytes)
        Relative paths (``"walk.bvh"``, ``"frames/000001.json"``) and their contents.
    """

    files: tuple[tuple[str, bytes], ...] = ()

    @property
    def size_bytes(self) -> int:
        """Bytes of every file together."""
        return sum(len(data) for _, data in self.files)

    def targets(self, root: Path) -> list[tuple[Path, bytes]]:
        """Where each file goes under ``root``, checked.

        Raises
        ------
        InputError
            For an absolute path or one with ``..``, or an empty one.
        """
        placed = []
        for name, data in self.files:
            relative = PurePosixPath(name)
            if relative.is_absolute() or ".." in relative.parts or not relative.parts:
                raise InputError(f"Expected a relative path inside the folder, got {name!r}")
            placed.append((root.joinpath(*relative.parts), data))
        return placed

    def unpack(self, root: Path) -> None:
        """Write every file under ``root`` (folders made as needed)."""
        for target, data in self.targets(root):
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)

    def __add__(self, other: SentFiles) -> SentFiles:
        return SentFiles(self.files + other.files)


def pack(root: Path, paths: Iterable[Path]) -> SentFiles:
    """The files at ``paths`` (each under ``root``), named relative to ``root``; a folder among
    them brings its files (one level: a take's frame folder)."""
    files: list[tuple[str, bytes]] = []
    for path in paths:
        members = sorted(p for p in path.iterdir() if p.is_file()) if path.is_dir() else [path]
        for member in members:
            files.append((member.relative_to(root).as_posix(), member.read_bytes()))
    return SentFiles(tuple(files))


def pack_tree(root: Path, folders: Iterable[str]) -> SentFiles:
    """Every file under the ``folders`` of ``root`` (relative POSIX names; missing folders add
    nothing), named relative to ``root``: a run's outputs on their way back."""
    files: list[tuple[str, bytes]] = []
    for folder in folders:
        base = root / folder
        if base.is_dir():
            for path in sorted(p for p in base.rglob("*") if p.is_file()):
                files.append((path.relative_to(root).as_posix(), path.read_bytes()))
    return SentFiles(tuple(files))


def probe_token(folder: Path) -> Path:
    """A new empty file in ``folder`` that only a worker sharing the folder can see (the caller
    removes it)."""
    folder.mkdir(parents=True, exist_ok=True)
    token = folder / f".share-probe-{uuid.uuid4().hex}"
    token.write_bytes(b"")
    return token


def sees(sample: str, size: int, mtime_ns: int, token: str | None) -> bool:
    """On a worker: whether it reads ``sample`` as the client does (same size and modification
    time) and, with a ``token``, sees that file and may write beside it."""
    try:
        status = os.stat(sample)
        if (status.st_size, status.st_mtime_ns) != (size, mtime_ns):
            return False
        if token is None:
            return True
        return os.path.isfile(token) and os.access(os.path.dirname(token), os.W_OK)
    except OSError:
        return False


def workers_share(client: Any, sample: Path, folder: Path | None) -> bool:
    """Whether every connected worker of ``client`` (a ``distributed.Client``) reads the
    client's ``sample`` file and, with a ``folder``, sees and may write in it.

    A cluster without workers yet counts as not sharing (bytes work everywhere).
    """
    status = sample.stat()
    token = probe_token(folder) if folder is not None else None
    try:
        answers = client.run(
            sees, str(sample), status.st_size, status.st_mtime_ns, str(token) if token else None
        )
    finally:
        if token is not None:
            token.unlink(missing_ok=True)
    return bool(answers) and all(answers.values())
