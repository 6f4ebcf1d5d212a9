"""Members ``zipfile`` cannot read (encrypted, Deflate64, damaged deflate or LZMA data) are
listed as unreadable, the other members unpacked; a ``.tar.gz`` whose gzip data are damaged is
an unreadable archive. Through the API: an import stores what it can and reports every part,
never a 500 after storing some."""

from __future__ import annotations

import io
import tarfile
from collections.abc import Iterator
from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import make_settings
from tests.api.test_hostile_pass import SMALL_BVH
from tests.io.test_damaged_zip import DAMAGES, damaged_zip, keypoint_npz

from mocapqa.api.app import create_app
from mocapqa.errors import InputError
from mocapqa.jobs.archive import unpack

LIMITS = {"max_members": 100, "max_bytes": 10_000_000}


@pytest.mark.parametrize("damage", DAMAGES)
def test_an_unreadable_zip_member_is_listed_and_the_others_unpacked(
    damage: str, tmp_path: Path
) -> None:
    members = {"a.bvh": SMALL_BVH, "bad.bvh": SMALL_BVH * 20, "c.bvh": SMALL_BVH}
    archive = tmp_path / "day.zip"
    archive.write_bytes(damaged_zip(damage, members, frozenset({"bad.bvh"})))
    dest = tmp_path / "out"
    dest.mkdir()
    unpacked = unpack(archive, archive.name, dest, **LIMITS)
    assert [m.name for m in unpacked] == ["a.bvh", "bad.bvh", "c.bvh"]
    good = [m for m in unpacked if m.name != "bad.bvh"]
    assert all(m.path is not None and m.path.read_bytes() == SMALL_BVH for m in good)
    bad = unpacked[1]
    assert bad.path is None
    assert str(bad.problem).startswith("unreadable member: ")
    assert sorted(p.name for p in dest.iterdir()) == sorted(
        m.path.name for m in good if m.path is not None
    )  # nothing of the unreadable member is left behind


def test_a_tar_gz_with_damaged_gzip_data_is_an_unreadable_archive(tmp_path: Path) -> None:
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz") as tar:
        for name in ("a.bvh", "b.bvh"):
            info = tarfile.TarInfo(name)
            info.size = len(SMALL_BVH)
            tar.addfile(info, io.BytesIO(SMALL_BVH))
    raw = bytearray(buffer.getvalue())
    raw[20:-20] = b"\xff" * (len(raw) - 40)  # past the gzip header, before its trailer
    archive = tmp_path / "day.tar.gz"
    archive.write_bytes(bytes(raw))
    dest = tmp_path / "out"
    dest.mkdir()
    with pytest.raises(InputError, match=r"Expected a readable \.tar\.gz archive"):
        unpack(archive, archive.name, dest, **LIMITS)


@pytest.fixture
def api(tmp_path: Path) -> Iterator[TestClient]:
    """A client of an app on a temporary SQLite store."""
    with TestClient(create_app(make_settings("sqlite", tmp_path))) as client:
        yield client


@pytest.mark.parametrize("damage", DAMAGES)
def test_an_import_reports_every_part_after_an_unreadable_member(
    api: TestClient, damage: str
) -> None:
    """First a take alone, then an archive holding a take, an unreadable member and an
    ``.npz`` whose own member is unreadable, then another take: 201, the three takes created,
    the two bad members failed by name, nothing else."""
    shoot = api.post("/api/v1/shoots", json={"name": f"day {damage}"}).json()
    archive = damaged_zip(
        damage,
        {
            "good.bvh": SMALL_BVH,
            "bad.bvh": SMALL_BVH * 20,
            "inner.npz": keypoint_npz(damage, frozenset({"positions.npy"})),
        },
        frozenset({"bad.bvh"}),
    )
    response = api.post(
        f"/api/v1/shoots/{shoot['id']}/takes",
        files=[
            ("files", ("first.bvh", SMALL_BVH)),
            ("files", ("day.zip", archive)),
            ("files", ("last.bvh", SMALL_BVH)),
        ],
    )
    assert response.status_code == 201, response.text
    report = response.json()
    assert [c["name"] for c in report["created"]] == ["first.bvh", "good.bvh", "last.bvh"]
    failed = {f["name"]: f["error"] for f in report["failed"]}
    assert set(failed) == {"day.zip:bad.bvh", "day.zip:inner.npz"}
    assert failed["day.zip:bad.bvh"].startswith("unreadable member: ")
    assert "Expected a readable .npz archive" in failed["day.zip:inner.npz"]
    assert "inner.npz" in failed["day.zip:inner.npz"]
    stored = api.get(f"/api/v1/shoots/{shoot['id']}").json()
    assert stored["n_takes"] == 3


def test_an_intact_npz_member_of_the_same_archive_is_imported(api: TestClient) -> None:
    """The damaged archives' builder leaves untouched members readable: its control."""
    shoot = api.post("/api/v1/shoots", json={"name": "control"}).json()
    archive = damaged_zip(
        "deflate", {"inner.npz": keypoint_npz("deflate", frozenset())}, frozenset()
    )
    response = api.post(
        f"/api/v1/shoots/{shoot['id']}/takes", files=[("files", ("day.zip", archive))]
    )
    assert response.status_code == 201, response.text
    assert [c["name"] for c in response.json()["created"]] == ["inner.npz"]
    assert api.get(f"/api/v1/shoots/{shoot['id']}").json()["n_takes"] == 1
