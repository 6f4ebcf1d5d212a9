"""Unpacking an uploaded archive (``.zip``, ``.tar.gz``) of takes, defensively.

Before anything is extracted, the member list is checked against the limits (member count and
total unpacked size as declared); while extracting, the bytes actually written are counted
again, so a header that lies about sizes is caught too. Members are never extracted by their
own path: each regular file is streamed to a fresh name in the destination folder, so a member
named ``../x`` or ``/etc/x`` cannot escape it (such members are reported, not written).
Symbolic and hard links, devices and other non-regular members are reported and skipped.
"""

from __future__ import annotations

import stat
import tarfile
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import IO

from mocapqa.errors import InputError, TooLargeError

__all__ = ["ARCHIVE_SUFFIXES", "Member", "archive_kind", "unpack"]

ARCHIVE_SUFFIXES = (".zip", ".tar.gz", ".tgz")
"""File names ending in these are unpacked on import."""
CHUNK = 1 << 20


@dataclass(frozen=True, slots=True)
class Member:
    """One archive member after unpacking.

    Parameters
    ----------
    name : str
        The member's name in the archive.
    path : Path, optional
        Where its bytes were written (None when it was not extracted).
    problem : str, optional
        Why it was not extracted (unsafe name, link, not a regular file).
    """

    name: str
    path: Path | None
    problem: str | None = None


def archive_kind(name: str) -> str | None:
    """``"zip"``, ``"tar"`` or None, from an uploaded file's name."""
    lower = name.lower()
    if lower.endswith(".zip"):
        return "zip"
    if lower.endswith((".tar.gz", ".tgz")):
        return "tar"
    return None


def _unsafe_name(name: str) -> str | None:
    pure = PurePosixPath(name.replace("\\", "/"))
    if pure.is_absolute() or (name[1:2] == ":" and name[:1].isalpha()):
        return "absolute path in the archive"
    if ".." in pure.parts:
        return "path leaves the archive folder ('..')"
    return None


def _copy(source: IO[bytes], target: Path, budget: list[int], limit: int) -> None:
    with target.open("wb") as out:
        while chunk := source.read(CHUNK):
            budget[0] += len(chunk)
            if budget[0] > limit:
                raise TooLargeError(
                    f"Expected an archive unpacking to at most {limit} bytes (setting "
                    "archive_max_unpacked_mb), got more"
                )
            out.write(chunk)


def _check_totals(count: int, declared: int, max_members: int, max_bytes: int) -> None:
    if count > max_members:
        raise TooLargeError(
            f"Expected an archive of at most {max_members} members (setting "
            f"archive_max_members), got {count}"
        )
    if declared > max_bytes:
        raise TooLargeError(
            f"Expected an archive unpacking to at most {max_bytes} bytes (setting "
            f"archive_max_unpacked_mb), got {declared} declared"
        )


def _zip_members(path: Path, dest: Path, max_members: int, max_bytes: int) -> Iterator[Member]:
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError) as e:
        raise InputError(f"Expected a readable .zip archive, got {e}") from e
    with archive:
        infos = [i for i in archive.infolist() if not i.is_dir()]
        _check_totals(len(infos), sum(i.file_size for i in infos), max_members, max_bytes)
        budget = [0]
        for index, info in enumerate(infos):
            mode = info.external_attr >> 16
            problem = _unsafe_name(info.filename)
            if problem is None and stat.S_ISLNK(mode):
                problem = "symbolic link"
            if problem is not None:
                yield Member(info.filename, None, problem)
                continue
            target = dest / f"{index:06d}"
            try:
                with archive.open(info) as source:
                    _copy(source, target, budget, max_bytes)
            except TooLargeError:
                raise
            except (zipfile.BadZipFile, OSError, EOFError, ValueError) as e:
                target.unlink(missing_ok=True)
                yield Member(info.filename, None, f"unreadable member: {e}")
                continue
            yield Member(info.filename, target)


def _tar_members(path: Path, dest: Path, max_members: int, max_bytes: int) -> Iterator[Member]:
    try:
        archive = tarfile.open(path, mode="r:*")  # noqa: SIM115 - closed by the with below
    except (tarfile.TarError, OSError, EOFError) as e:
        raise InputError(f"Expected a readable .tar.gz archive, got {e}") from e
    with archive:
        infos: list[tarfile.TarInfo] = []
        declared = 0
        try:
            for info in archive:  # headers only; stops as soon as a limit is passed
                if info.isdir():
                    continue
                infos.append(info)
                declared += info.size if info.isfile() else 0
                _check_totals(len(infos), declared, max_members, max_bytes)
        except (tarfile.TarError, OSError, EOFError) as e:
            raise InputError(f"Expected a readable .tar.gz archive, got {e}") from e
        budget = [0]
        for index, info in enumerate(infos):
            problem = _unsafe_name(info.name)
            if problem is None and info.issym():
                problem = "symbolic link"
            elif problem is None and info.islnk():
                problem = "hard link"
            elif problem is None and not info.isfile():
                problem = "not a regular file"
            if problem is not None:
                yield Member(info.name, None, problem)
                continue
            target = dest / f"{index:06d}"
            try:
                source = archive.extractfile(info)
                if source is None:
                    yield Member(info.name, None, "not a regular file")
                    continue
                with source:
                    _copy(source, target, budget, max_bytes)
            except TooLargeError:
                raise
            except (tarfile.TarError, OSError, EOFError, ValueError) as e:
                target.unlink(missing_ok=True)
                yield Member(info.name, None, f"unreadable member: {e}")
                continue
            yield Member(info.name, target)


def unpack(path: Path, name: str, dest: Path, max_members: int, max_bytes: int) -> list[Member]:
    """Unpack an archive's regular files into ``dest`` (one fresh file name per member).

    Parameters
    ----------
    path : Path
        The archive as received.
    name : str
        Its client-side name (decides zip or tar).
    dest : Path
        An empty folder.
    max_members : int
        Most members (folders excluded) accepted.
    max_bytes : int
        Most bytes the members may unpack to, declared and actually written.

    Raises
    ------
    TooLargeError
        When a limit is passed (nothing is imported then).
    InputError
        When the archive itself is unreadable.
    """
    kind = archive_kind(name)
    if kind is None:
        raise InputError(
            f"Expected an archive ending in {', '.join(ARCHIVE_SUFFIXES)}, got {name!r}"
        )
    reader = _zip_members if kind == "zip" else _tar_members
    return list(reader(path, dest, max_members, max_bytes))
