"""Zip archives ``zipfile`` cannot read (an encrypted member, Deflate64, damaged deflate or LZMA
data) are unreadable ``.npz`` takes: ParseError naming the file (422 through the API), never a
500 from the library's own exception."""

from __future__ import annotations

import io
import lzma
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import make_settings

from mocapqa.api.app import create_app
from mocapqa.errors import ParseError
from mocapqa.io.formats import read_take
from mocapqa.io.guards import ReadLimits, check_take_input
from mocapqa.io.keypoint_arrays import parse_keypoint_npz

DAMAGES = ("encrypted", "deflate64", "deflate", "lzma")
"""How :func:`damaged_zip` spoils its members."""

RAISED: dict[str, type[Exception]] = {
    "encrypted": RuntimeError,
    "deflate64": NotImplementedError,
    "deflate": zlib.error,
    "lzma": lzma.LZMAError,
}
"""What :mod:`zipfile` raises reading a member of each damage."""


def npy_bytes(array: np.ndarray) -> bytes:
    """An array as the bytes of a ``.npy`` file."""
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def _records(raw: bytes, signature: bytes) -> list[int]:
    """Offsets of the local (``PK\\3\\4``) or central (``PK\\1\\2``) records of a zip."""
    found, at = [], raw.find(signature)
    while at >= 0:
        found.append(at)
        at = raw.find(signature, at + 4)
    return found


def damaged_zip(damage: str, members: dict[str, bytes], spoiled: frozenset[str]) -> bytes:
    """A zip of ``members`` whose members named in ``spoiled`` are made unreadable by
    ``damage`` (one of :data:`DAMAGES`), the others left intact.

    * ``encrypted``: the encrypted bit (0) of the general-purpose flags set, in the local and
      the central record;
    * ``deflate64``: compression method 9 written in both records;
    * ``deflate``: the deflated data overwritten with 0xFF (a reserved block type);
    * ``lzma``: an LZMA member whose data after its 9-byte properties header are overwritten.
    """
    method = zipfile.ZIP_LZMA if damage == "lzma" else zipfile.ZIP_DEFLATED
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", method) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    raw = bytearray(buffer.getvalue())
    with zipfile.ZipFile(io.BytesIO(bytes(raw))) as archive:
        infos = {i.header_offset: i for i in archive.infolist()}
    locals_ = _records(bytes(raw), b"PK\x03\x04")
    centrals = _records(bytes(raw), b"PK\x01\x02")
    for local, central in zip(locals_, centrals, strict=True):
        info = infos[local]
        if info.filename not in spoiled:
            continue
        if damage == "encrypted":
            raw[local + 6] |= 1
            raw[central + 8] |= 1
        elif damage == "deflate64":
            raw[local + 8 : local + 10] = (9).to_bytes(2, "little")
            raw[central + 10 : central + 12] = (9).to_bytes(2, "little")
        else:
            names = int.from_bytes(raw[local + 26 : local + 28], "little")
            extra = int.from_bytes(raw[local + 28 : local + 30], "little")
            start = local + 30 + names + extra + (9 if damage == "lzma" else 0)
            end = local + 30 + names + extra + info.compress_size
            raw[start:end] = b"\xff" * (end - start)
    return bytes(raw)


def keypoint_npz(damage: str, spoiled: frozenset[str]) -> bytes:
    """A keypoint ``.npz`` (positions, fps, names) with ``spoiled`` members damaged."""
    members = {
        "positions.npy": npy_bytes(np.zeros((20, 3, 3))),
        "fps.npy": npy_bytes(np.array(30.0)),
        "names": npy_bytes(np.array(["a", "b", "c"])),  # no .npy: read by NumPy, not checked
    }
    return damaged_zip(damage, members, spoiled)


@pytest.mark.parametrize("damage", DAMAGES)
def test_the_damaged_members_raise_what_zipfile_raises(damage: str) -> None:
    data = keypoint_npz(damage, frozenset({"positions.npy"}))
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert archive.read("fps.npy") == npy_bytes(np.array(30.0))  # the others are intact
        with pytest.raises(RAISED[damage]):
            archive.read("positions.npy")


@pytest.mark.parametrize("damage", DAMAGES)
def test_a_damaged_npz_member_is_a_parse_error_before_reading(damage: str, tmp_path: Path) -> None:
    path = tmp_path / f"take_{damage}.npz"
    path.write_bytes(keypoint_npz(damage, frozenset({"positions.npy"})))
    with pytest.raises(ParseError, match=r"Expected a readable \.npz archive") as raised:
        check_take_input(path, "npz", ReadLimits())
    assert path.name in str(raised.value)
    for limits in (None, ReadLimits()):
        with pytest.raises(ParseError, match=r"Expected a readable \.npz archive"):
            read_take(path, limits=limits)


@pytest.mark.parametrize("damage", DAMAGES)
def test_a_damaged_member_numpy_reads_itself_is_a_parse_error(damage: str) -> None:
    """A member without ``.npy`` is not opened by the header checks: NumPy's read fails."""
    data = keypoint_npz(damage, frozenset({"names"}))
    with pytest.raises(ParseError, match=r"Expected a readable \.npz archive") as raised:
        parse_keypoint_npz(data, "named.npz")
    assert "named.npz" in str(raised.value)


@pytest.fixture
def api(tmp_path: Path) -> Iterator[TestClient]:
    """A client of an app on a temporary SQLite store."""
    with TestClient(create_app(make_settings("sqlite", tmp_path))) as client:
        yield client


@pytest.mark.parametrize("damage", DAMAGES)
def test_a_damaged_npz_upload_is_422_naming_the_file(api: TestClient, damage: str) -> None:
    client = api
    data = keypoint_npz(damage, frozenset({"positions.npy"}))
    response = client.post("/api/v1/takes", files={"file": ("broken.npz", data)})
    assert response.status_code == 422, response.text
    detail = str(response.json()["detail"])
    assert "Expected a readable .npz archive" in detail
    assert "broken.npz" in detail
    assert client.get("/api/v1/takes").json()["items"] == []
