"""Unpacking an uploaded archive (``.zip``, ``.tar.gz``) of takes, defensively.

Before anything is extracted, the member list is checked against the limits (member count and
total unpacked size as declared); while extracting, the bytes actually written are counted
again, so a header that lies about sizes is caught too. Members are never extracted by their
own path: each regular file is streamed to a fresh name in the destination folder, so a member
named ``../x`` or ``/etc/x`` cannot escape it (such members are reported, not written).
Symbolic and hard links, devices and other non-regular members are reported and skipped.

A tar archive's headers are first read straight from its (decompressed) byte stream, before
:mod:`tarfile` sees it: ``tarfile`` reads a GNU long-name or pax header's whole payload into
memory, so a 1.4 MB ``.tar.gz`` declaring a 1.5 GB long name made the server allocate 1.4 GB.
Such headers over :data:`MAX_META_BYTES`, and archives whose stream passes the unpacked limit,
are refused before ``tarfile`` opens them.
"""

from __future__ import annotations

import bz2
import gzip
import io
import lzma
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
MAX_META_BYTES = 1 << 16
"""Largest GNU long-name/long-link or pax extended header payload of a tar member, bytes (a
path of 64 KiB is far beyond any file system's)."""
_META_TYPES = frozenset(b"LKxg")  # GNU long name, long link; pax extended, pax global
_BLOCK = 512


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


def _decompressed(path: Path) -> io.BufferedIOBase:
    """The tar stream of ``path``: gzip, bzip2 or xz by their magic bytes, else the file."""
    with path.open("rb") as probe:
        magic = probe.read(6)
    if magic[:2] == b"\x1f\x8b":
        return gzip.GzipFile(path, "rb")
    if magic[:3] == b"BZh":
        return bz2.open(path, "rb")
    if magic == b"\xfd7zXZ\x00":
        return lzma.open(path, "rb")
    return path.open("rb")


def _header_size(field: bytes) -> int:
    """A tar header's size field: octal text, or base-256 when its first byte has bit 7 set."""
    if field[:1] and field[0] & 0x80:
        return int.from_bytes(bytes([field[0] & 0x7F]) + field[1:], "big")
    text = field.replace(b"\x00", b" ").strip()
    return int(text, 8) if text else 0


def _scan_tar_headers(path: Path, max_members: int, max_bytes: int) -> None:
    """Walk the tar stream's headers without keeping any payload in memory.

    Raises
    ------
    TooLargeError
        A long-name or pax header over :data:`MAX_META_BYTES`, more headers than the member
        limit allows for, or a stream longer than the unpacked limit (plus its headers).
    InputError
        A stream that is not a tar archive (a header whose size field is not a number).
    """
    headers, streamed = 0, 0
    budget = max_bytes + _BLOCK * (4 * max_members + 4)  # payloads plus their headers
    try:
        with _decompressed(path) as stream:
            while (header := stream.read(_BLOCK)) and len(header) == _BLOCK:
                if header == b"\x00" * _BLOCK:
                    return  # the end-of-archive marker
                headers += 1
                # A member has at most a pax and two GNU headers before its own.
                if headers > 4 * max_members + 4:
                    raise TooLargeError(
                        f"Expected an archive of at most {max_members} members (setting "
                        "archive_max_members), got more headers than that allows"
                    )
                try:
                    size = _header_size(header[124:136])
                except ValueError as e:
                    raise InputError(f"Expected a tar archive, got a header size {e}") from e
                if header[156] in _META_TYPES and size > MAX_META_BYTES:
                    raise TooLargeError(
                        f"Expected tar name and pax headers of at most {MAX_META_BYTES} bytes, "
                        f"got one of {size}"
                    )
                left = -(-size // _BLOCK) * _BLOCK
                streamed += _BLOCK + left
                if streamed > budget:
                    raise TooLargeError(
                        f"Expected an archive unpacking to at most {max_bytes} bytes (setting "
                        "archive_max_unpacked_mb), got more"
                    )
                while left > 0:
                    skipped = len(stream.read(min(left, CHUNK)))
                    if skipped == 0:
                        return  # truncated: tarfile reports it below
                    left -= skipped
    except (OSError, EOFError, lzma.LZMAError) as e:
        raise InputError(f"Expected a readable .tar.gz archive, got {e}") from e


def _tar_members(path: Path, dest: Path, max_members: int, max_bytes: int) -> Iterator[Member]:
    _scan_tar_headers(path, max_members, max_bytes)
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
