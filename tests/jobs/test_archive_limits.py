"""Archive limits paid before their cost (issue 32): a zip's member count read from its end
records (and checked against its central directory's headers) before :mod:`zipfile` parses the
directory, directories counted as members in zips and tars, and each member capped at the
upload limit while it is written (the member listed as failed, the others unpacked)."""

from __future__ import annotations

import io
import struct
import tarfile
import zipfile
from pathlib import Path
from typing import Any, NoReturn

import pytest

from mocapqa.errors import InputError, TooLargeError
from mocapqa.jobs.archive import unpack

SMALL = b"HIERARCHY\nROOT Hips\n"
"""A small member (its content is not read here)."""


def never(*args: Any, **kwargs: Any) -> NoReturn:
    raise AssertionError("the archive was opened by its library before the limits were checked")


def write_zip(path: Path, members: dict[str, bytes], dirs: int = 0) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for i in range(dirs):
            archive.writestr(f"folder{i}/", b"")
        for name, data in members.items():
            archive.writestr(name, data)
    return path


def write_tar(path: Path, members: dict[str, bytes], dirs: int = 0) -> Path:
    with tarfile.open(path, "w:gz") as archive:
        for i in range(dirs):
            folder = tarfile.TarInfo(f"folder{i}")
            folder.type = tarfile.DIRTYPE
            archive.addfile(folder)
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            archive.addfile(info, io.BytesIO(data))
    return path


def zip64_end(entries: int, cd_size: int) -> bytes:
    """A zip of nothing but its end records: a zip64 one claiming ``entries`` members in a
    central directory of ``cd_size`` bytes, its locator, and the classic one saying 0xFFFF."""
    record = struct.pack(
        "<4sQ2H2L4Q", b"PK\x06\x06", 44, 45, 45, 0, 0, entries, entries, cd_size, 0
    )
    locator = struct.pack("<4sLQL", b"PK\x06\x07", 0, 0, 1)
    classic = struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, 0xFFFF, 0xFFFF, 0xFFFFFFFF, 0, 0)
    return record + locator + classic


def test_zip_folders_count_against_the_member_limit(tmp_path: Path) -> None:
    """A zip of 300,000 folder entries was accepted: folders were not counted."""
    path = write_zip(tmp_path / "a.zip", {"t.bvh": SMALL}, dirs=5)
    with pytest.raises(TooLargeError, match=r"at most 3 members \(setting archive_max_members\)"):
        unpack(path, "a.zip", tmp_path, 3, 10**6)


def test_a_zip_claiming_millions_of_members_is_refused_before_zipfile_opens_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """zipfile parses the whole central directory when it opens an archive (2,000,000 entries:
    12 s, ~1 GB); the count in the zip64 end record is refused before it is called."""
    path = tmp_path / "claims.zip"
    path.write_bytes(zip64_end(2_000_000, 174_000_000))
    monkeypatch.setattr(zipfile, "ZipFile", never)
    with pytest.raises(TooLargeError, match="archive_max_members\\), got 2000000"):
        unpack(path, "claims.zip", tmp_path, 100_000, 10**9)


def test_a_zip_whose_end_record_understates_its_members_is_refused_from_its_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """zipfile reads entries until the directory's declared size is used up, whatever count
    the end record gives: a count of 2 over a directory of 50 entries is caught by walking the
    entries' fixed headers (bounded by the limit), before zipfile reads the directory. The end
    record is found behind a comment (up to 64 KiB), as zipfile finds it."""
    path = tmp_path / "lies.zip"
    with zipfile.ZipFile(path, "w") as archive:
        archive.comment = b"PK" * 30_000
        for i in range(50):
            archive.writestr(f"t{i}.bvh", SMALL)
    data = bytearray(path.read_bytes())
    end = data.rfind(b"PK\x05\x06")
    data[end + 8 : end + 12] = struct.pack("<2H", 2, 2)
    path.write_bytes(bytes(data))
    monkeypatch.setattr(zipfile, "ZipFile", never)
    with pytest.raises(TooLargeError, match="at most 10 members"):
        unpack(path, "lies.zip", tmp_path, 10, 10**6)


def test_a_zip64_archive_is_counted_from_its_zip64_record(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The classic end record of a zip64 archive may say 0xFFFF: the zip64 record's count is
    the one checked (as zipfile reads it): 11 members are refused by a limit of 10 before
    zipfile opens the archive, 3 members pass it."""
    paths = {}
    with monkeypatch.context() as patched:
        patched.setattr(zipfile, "ZIP_FILECOUNT_LIMIT", 1)  # zipfile writes zip64 records
        for n in (3, 11):
            path = write_zip(tmp_path / f"z{n}.zip", {f"t{i}.bvh": SMALL for i in range(n)})
            data = bytearray(path.read_bytes())
            assert data.rfind(b"PK\x06\x06") >= 0
            end = data.rfind(b"PK\x05\x06")
            data[end + 8 : end + 12] = struct.pack("<2H", 0xFFFF, 0xFFFF)
            path.write_bytes(bytes(data))
            paths[n] = path
    with monkeypatch.context() as patched:
        patched.setattr(zipfile, "ZipFile", never)
        with pytest.raises(TooLargeError, match="archive_max_members\\), got 11"):
            unpack(paths[11], "z.zip", tmp_path, 10, 10**6)
    members = unpack(paths[3], "z.zip", tmp_path, 10, 10**6)
    assert [m.name for m in members if m.path is not None] == ["t0.bvh", "t1.bvh", "t2.bvh"]


def test_a_zip_whose_directory_is_damaged_is_unreadable_before_zipfile_reads_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = write_zip(tmp_path / "d.zip", {"t.bvh": SMALL, "u.bvh": SMALL})
    data = bytearray(path.read_bytes())
    start = data.rfind(b"PK\x01\x02")
    data[start : start + 4] = b"XXXX"
    path.write_bytes(bytes(data))
    monkeypatch.setattr(zipfile, "ZipFile", never)
    with pytest.raises(InputError, match=r"Expected a readable \.zip archive, got a damaged"):
        unpack(path, "d.zip", tmp_path, 10, 10**6)


def test_tar_folders_count_against_the_member_limit_before_tarfile_opens_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The header scan counts every member, folders too, and stops at the first past the
    limit: tarfile never opens the archive."""
    path = write_tar(tmp_path / "a.tar.gz", {"t.bvh": SMALL}, dirs=10)
    monkeypatch.setattr(tarfile, "open", never)
    with pytest.raises(TooLargeError, match=r"at most 3 members \(setting archive_max_members\)"):
        unpack(path, "a.tar.gz", tmp_path, 3, 10**6)


@pytest.mark.parametrize("kind", ["zip", "tar"])
def test_a_member_over_the_upload_limit_is_failed_and_never_written_whole(
    kind: str, tmp_path: Path
) -> None:
    """One highly compressible member larger than the upload limit was written whole before
    being refused (1.9 GB from a 1.8 MB zip): it is now cut at the limit, its partial file
    removed and the member listed as failed; the other members are unpacked."""
    limit = 10_000
    members = {"a.bvh": SMALL, "zeros.bvh": bytes(1_000_000), "b.bvh": SMALL}
    name = f"m.{'zip' if kind == 'zip' else 'tar.gz'}"
    path = (write_zip if kind == "zip" else write_tar)(tmp_path / name, members)
    assert path.stat().st_size < limit
    dest = tmp_path / "out"
    dest.mkdir()
    unpacked = unpack(path, name, dest, 10, 10**7, max_member_bytes=limit)
    problems = {m.name: m.problem for m in unpacked}
    assert problems["a.bvh"] is None
    assert problems["b.bvh"] is None
    assert problems["zeros.bvh"] == (
        f"Expected a member of at most {limit} bytes (the upload limit, setting max_upload_mb), "
        "got more"
    )
    assert sorted(p.stat().st_size for p in dest.iterdir()) == [len(SMALL), len(SMALL)]


def test_the_declared_total_is_given_before_anything_is_written(tmp_path: Path) -> None:
    """The caller hears the declared unpacked total once the limits pass and before the first
    member is written, so it can refuse (a per-user quota of staged bytes)."""
    path = write_zip(tmp_path / "t.zip", {"a.bvh": SMALL, "b.bvh": SMALL * 2}, dirs=1)
    dest = tmp_path / "out"
    dest.mkdir()
    seen: list[tuple[int, int]] = []

    def before_extract(total: int) -> None:
        seen.append((total, len(list(dest.iterdir()))))

    unpack(path, "t.zip", dest, 10, 10**6, before_extract=before_extract)
    assert seen == [(3 * len(SMALL), 0)]
