"""Unpacking an uploaded archive (``.zip``, ``.tar.gz``) of takes, defensively.

Before anything is extracted, the member list is checked against the limits (member count,
folders included, and total unpacked size as declared); while extracting, the bytes actually
written are counted again, so a header that lies about sizes is caught too, and each member is
cut at the largest single upload (``max_member_bytes``): a member passing it is removed and
reported, the others are unpacked. Members are never extracted by their
own path: each regular file is streamed to a fresh name in the destination folder, so a member
named ``../x`` or ``/etc/x`` cannot escape it (such members are reported, not written).
Symbolic and hard links, devices and other non-regular members are reported and skipped.

A tar archive's headers are first read straight from its (decompressed) byte stream, before
:mod:`tarfile` sees it: ``tarfile`` reads a GNU long-name or pax header's whole payload into
memory, so a 1.4 MB ``.tar.gz`` declaring a 1.5 GB long name made the server allocate 1.4 GB.
Such headers over :data:`MAX_META_BYTES`, archives of more members than the limit (counted
header by header, stopping at the first past it) and archives whose stream passes the unpacked
limit are refused before ``tarfile`` opens them.

A zip's member count is likewise checked before :mod:`zipfile` opens it: ``zipfile.ZipFile``
reads the whole central directory into memory and makes an object per entry (2,000,000 entries
in a 174 MB zip took 12 s and ~1 GB before the count could be checked). The end record (and the
zip64 one) are read from the file's tail, found as ``zipfile`` finds them; their entry count is
checked, then the directory's entries are walked by their fixed 46-byte headers, as far as
``zipfile`` would read, stopping at the first past the limit: ``zipfile`` reads entries until
the directory's declared size is used up, whatever count the end record gives.
"""

from __future__ import annotations

import bz2
import functools
import gzip
import io
import lzma
import stat
import struct
import tarfile
import zipfile
import zlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import IO

from mocapqa.errors import InputError, TooLargeError
from mocapqa.io.guards import ZIP_READ_ERRORS

__all__ = ["ARCHIVE_SUFFIXES", "Member", "archive_kind", "unpack"]

ARCHIVE_SUFFIXES = (".zip", ".tar.gz", ".tgz")
"""File names ending in these are unpacked on import."""
CHUNK = 1 << 20
MAX_META_BYTES = 1 << 16
"""Largest GNU long-name/long-link or pax extended header payload of a tar member, bytes (a
path of 64 KiB is far beyond any file system's)."""
_META_TYPES = frozenset(b"LKxg")  # GNU long name, long link; pax extended, pax global
_BLOCK = 512
# The zip records zipfile reads to find the central directory (APPNOTE 4.3.12-4.3.16).
_END = struct.Struct("<4s4H2LH")  # end of central directory; its comment follows (< 64 KiB)
_END64_LOCATOR = struct.Struct("<4sLQL")  # just before the end record
_END64 = struct.Struct("<4sQ2H2L4Q")  # just before its locator (no extensible data)
_CENTRAL = struct.Struct("<4s4B4HL2L5H2L")  # an entry's fixed part: name, extra, comment follow
_TAIL_BYTES = _END.size + (1 << 16)


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


def _member_too_large(limit: int) -> str:
    return (
        f"Expected a member of at most {limit} bytes (the upload limit, setting max_upload_mb), "
        "got more"
    )


def _copy(source: IO[bytes], target: Path, budget: list[int], limit: int, member: int) -> bool:
    """Stream a member to ``target``, counting against the archive's ``budget``; False (with
    ``target`` removed) when the member passes ``member`` bytes: nothing past it is read or
    written."""
    written = 0
    with target.open("wb") as out:
        while chunk := source.read(min(CHUNK, member + 1 - written)):
            written += len(chunk)
            if written > member:
                break
            budget[0] += len(chunk)
            if budget[0] > limit:
                raise TooLargeError(
                    f"Expected an archive unpacking to at most {limit} bytes (setting "
                    "archive_max_unpacked_mb), got more"
                )
            out.write(chunk)
    if written > member:
        target.unlink(missing_ok=True)
        return False
    return True


def _too_many(max_members: int, got: str) -> TooLargeError:
    return TooLargeError(
        f"Expected an archive of at most {max_members} members (setting archive_max_members), "
        f"got {got}"
    )


def _check_totals(count: int, declared: int, max_members: int, max_bytes: int) -> None:
    if count > max_members:
        raise _too_many(max_members, str(count))
    if declared > max_bytes:
        raise TooLargeError(
            f"Expected an archive unpacking to at most {max_bytes} bytes (setting "
            f"archive_max_unpacked_mb), got {declared} declared"
        )


def _end_record(handle: IO[bytes]) -> tuple[int, int, int] | None:
    """The central directory's entry count, size and start, from the end records at the tail
    of a zip, found as :mod:`zipfile` finds them (``_EndRecData``); None when there is none
    (``zipfile`` then says what is wrong). At most 64 KiB + 98 bytes are read."""
    size = handle.seek(0, io.SEEK_END)
    if size < _END.size:
        return None
    first = max(size - _TAIL_BYTES, 0)
    handle.seek(first)
    tail = handle.read()
    at = len(tail) - _END.size
    if not (tail[at : at + 4] == b"PK\x05\x06" and tail[-2:] == b"\x00\x00"):
        at = tail.rfind(b"PK\x05\x06")  # behind a comment
        if at < 0 or len(tail) - at < _END.size:
            return None
    _, _, _, _, count, cd_size, _, _ = _END.unpack_from(tail, at)
    position = first + at
    if position >= _END64_LOCATOR.size + _END64.size:
        handle.seek(position - _END64_LOCATOR.size - _END64.size)
        before = handle.read(_END64.size + _END64_LOCATOR.size)
        locator = _END64_LOCATOR.unpack_from(before, _END64.size)
        record = _END64.unpack_from(before)
        if locator[0] == b"PK\x06\x07" and record[0] == b"PK\x06\x06":
            count, cd_size = record[7], record[8]
            position -= _END64_LOCATOR.size + _END64.size
    # zipfile's start of the directory: offset + "concat", which is the end record's (or the
    # zip64 record's) position less the directory's size, whatever the declared offset.
    return count, cd_size, position - cd_size


def _check_zip_directory(path: Path, max_members: int) -> None:
    """Refuse a zip of more members than ``max_members`` (folders too) before :mod:`zipfile`
    reads its central directory: the end record's count first, then the entries ``zipfile``
    would read, walked by their fixed headers, stopping at the first past the limit.

    Raises
    ------
    TooLargeError
        More entries than the limit, declared or found.
    InputError
        A directory whose entries do not fill its declared size (``zipfile`` would refuse
        it too, after reading all of it).
    """
    with path.open("rb") as handle:
        found = _end_record(handle)
        if found is None:
            return
        count, cd_size, start = found
        if count > max_members:
            raise _too_many(max_members, str(count))
        if start < 0:
            return  # zipfile refuses it before reading anything
        handle.seek(start)
        walked, entries = 0, 0
        while walked < cd_size:
            fixed = handle.read(_CENTRAL.size) if walked + _CENTRAL.size <= cd_size else b""
            if len(fixed) != _CENTRAL.size or fixed[:4] != b"PK\x01\x02":
                raise InputError(
                    "Expected a readable .zip archive, got a damaged central directory (entry "
                    f"{entries + 1} at byte {start + walked})"
                )
            entries += 1
            if entries > max_members:
                raise _too_many(max_members, f"more in its central directory ({count} declared)")
            lengths = sum(struct.unpack_from("<3H", fixed, 28))  # name, extra, comment
            walked += _CENTRAL.size + lengths
            handle.seek(lengths, io.SEEK_CUR)


_ZIP_DAMAGE = ZIP_READ_ERRORS
"""What reading a damaged zip member raises: besides damaged data (``zlib.error``,
``lzma.LZMAError``, bzip2's ``OSError``, a bad CRC), an encrypted member (``RuntimeError``) and
a compression method :mod:`zipfile` lacks (``NotImplementedError``, Deflate64)."""
_TAR_DAMAGE = (tarfile.TarError, OSError, EOFError, ValueError, zlib.error, lzma.LZMAError)
"""What reading a damaged tar member raises (damaged gzip data: ``zlib.error``)."""
_Entry = tuple[str, str | None, Callable[[], IO[bytes] | None]]
"""A member to unpack: its name, why it is not unpacked (None: it is) and its stream's opener."""


def _extract(
    name: str,
    target: Path,
    opened: Callable[[], IO[bytes] | None],
    damaged: tuple[type[Exception], ...],
    budget: list[int],
    limits: tuple[int, int],
) -> Member:
    """A member (its name found safe) copied to ``target`` from the stream ``opened`` gives
    (None: not a regular file), within ``budget`` and ``limits`` (the archive's unpacked
    bytes, the member's); a member whose read raises one of ``damaged`` is unreadable.

    Raises
    ------
    TooLargeError
        When the archive unpacks to more than its limit.
    """
    max_bytes, max_member_bytes = limits
    try:
        source = opened()
        if source is None:
            return Member(name, None, "not a regular file")
        with source:
            whole = _copy(source, target, budget, max_bytes, max_member_bytes)
    except TooLargeError:
        raise
    except damaged as e:
        target.unlink(missing_ok=True)
        return Member(name, None, f"unreadable member: {e}")
    if not whole:
        return Member(name, None, _member_too_large(max_member_bytes))
    return Member(name, target)


def _zip_problem(info: zipfile.ZipInfo) -> str | None:
    """Why a zip member is not unpacked (an unsafe name, a symbolic link), or None."""
    problem = _unsafe_name(info.filename)
    if problem is None and stat.S_ISLNK(info.external_attr >> 16):
        problem = "symbolic link"
    return problem


@contextmanager
def _zip_entries(
    path: Path, max_members: int, max_bytes: int
) -> Iterator[tuple[int, Iterator[_Entry]]]:
    """The open zip's declared unpacked total and its members, folders left out, once both
    are found within the limits (raising as :func:`unpack`)."""
    try:
        _check_zip_directory(path, max_members)
        archive = zipfile.ZipFile(path)
    except ZIP_READ_ERRORS as e:
        raise InputError(f"Expected a readable .zip archive, got {e}") from e
    with archive:
        listed = archive.infolist()
        infos = [i for i in listed if not i.is_dir()]
        declared = sum(i.file_size for i in infos)
        _check_totals(len(listed), declared, max_members, max_bytes)
        yield (
            declared,
            ((i.filename, _zip_problem(i), functools.partial(archive.open, i)) for i in infos),
        )


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
        A long-name or pax header over :data:`MAX_META_BYTES`, more members than the limit
        (folders too; the scan stops at the first past it) or more headers than they allow
        for, or a stream longer than the unpacked limit (plus its headers).
    InputError
        A stream that is not a tar archive (a header whose size field is not a number).
    """
    headers, members, streamed = 0, 0, 0
    budget = max_bytes + _BLOCK * (4 * max_members + 4)  # payloads plus their headers
    try:
        with _decompressed(path) as stream:
            while (header := stream.read(_BLOCK)) and len(header) == _BLOCK:
                if header == b"\x00" * _BLOCK:
                    return  # the end-of-archive marker
                headers += 1
                # A member has at most a pax and two GNU headers before its own.
                if headers > 4 * max_members + 4:
                    raise _too_many(max_members, "more headers than that allows")
                if header[156] not in _META_TYPES:
                    members += 1  # every entry, folders too
                    if members > max_members:
                        raise _too_many(max_members, "more")
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
    except (OSError, EOFError, zlib.error, lzma.LZMAError) as e:
        raise InputError(f"Expected a readable .tar.gz archive, got {e}") from e


def _tar_problem(info: tarfile.TarInfo) -> str | None:
    """Why a tar member is not unpacked (an unsafe name, a link, not a regular file), or None."""
    problem = _unsafe_name(info.name)
    if problem is None and info.issym():
        problem = "symbolic link"
    elif problem is None and info.islnk():
        problem = "hard link"
    elif problem is None and not info.isfile():
        problem = "not a regular file"
    return problem


@contextmanager
def _tar_entries(
    path: Path, max_members: int, max_bytes: int
) -> Iterator[tuple[int, Iterator[_Entry]]]:
    """The open tar's declared unpacked total and its members, folders left out, once its
    headers and then both are found within the limits (raising as :func:`unpack`)."""
    _scan_tar_headers(path, max_members, max_bytes)
    try:
        archive = tarfile.open(path, mode="r:*")  # noqa: SIM115 - closed by the with below
    except (tarfile.TarError, OSError, EOFError, zlib.error, lzma.LZMAError) as e:
        raise InputError(f"Expected a readable .tar.gz archive, got {e}") from e
    with archive:
        infos: list[tarfile.TarInfo] = []
        entries, declared = 0, 0
        try:
            for info in archive:  # headers only; stops as soon as a limit is passed
                entries += 1  # folders count, as in the header scan
                if info.isdir():
                    continue
                infos.append(info)
                declared += info.size if info.isfile() else 0
                _check_totals(entries, declared, max_members, max_bytes)
        except (tarfile.TarError, OSError, EOFError, zlib.error, lzma.LZMAError) as e:
            raise InputError(f"Expected a readable .tar.gz archive, got {e}") from e
        yield (
            declared,
            ((i.name, _tar_problem(i), functools.partial(archive.extractfile, i)) for i in infos),
        )


def _extract_all(
    entries: Iterator[_Entry],
    dest: Path,
    damaged: tuple[type[Exception], ...],
    limits: tuple[int, int],
) -> list[Member]:
    """Each member reported with its problem, or else streamed to a fresh numbered file in
    ``dest`` (:func:`_extract`), all within one budget of unpacked bytes."""
    budget = [0]
    members = []
    for index, (name, problem, opened) in enumerate(entries):
        if problem is not None:
            members.append(Member(name, None, problem))
            continue
        target = dest / f"{index:06d}"
        members.append(_extract(name, target, opened, damaged, budget, limits))
    return members


def _nothing(declared: int) -> None:
    """The default ``before_extract``: nothing to refuse."""


def unpack(
    path: Path,
    name: str,
    dest: Path,
    max_members: int,
    max_bytes: int,
    *,
    max_member_bytes: int | None = None,
    before_extract: Callable[[int], None] = _nothing,
) -> list[Member]:
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
        Most members (folders included) accepted.
    max_bytes : int
        Most bytes the members may unpack to, declared and actually written.
    max_member_bytes : int, optional
        Most bytes one member may unpack to (the upload limit, ``max_upload_mb``): a member
        passing it is cut there while it is written, its file removed and the member
        reported with that problem (the others are unpacked). ``max_bytes`` when None.
    before_extract : callable, optional
        Called with the declared unpacked total once the limits are checked, before anything
        is written; what it raises refuses the archive (a per-user quota of staged bytes).

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
    entries_of, damaged = (
        (_zip_entries, _ZIP_DAMAGE) if kind == "zip" else (_tar_entries, _TAR_DAMAGE)
    )
    member = max_bytes if max_member_bytes is None else max_member_bytes
    with entries_of(path, max_members, max_bytes) as (declared, entries):
        before_extract(declared)
        return _extract_all(entries, dest, damaged, (max_bytes, member))
