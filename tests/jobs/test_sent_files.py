"""Files sent to and from workers that share no disk: packing, unpacking, refusals."""

from __future__ import annotations

from pathlib import Path

import pytest

from mocapqa.errors import InputError
from mocapqa.jobs.sent_files import SentFiles, pack, pack_tree, sees


def test_a_take_and_a_frame_folder_travel_by_relative_name(tmp_path: Path) -> None:
    (tmp_path / "walk.bvh").write_bytes(b"HIERARCHY")
    frames = tmp_path / "frames"
    frames.mkdir()
    for index in (2, 1):
        (frames / f"{index:06d}.json").write_bytes(b"{}" * index)
    sent = pack(tmp_path, [tmp_path / "walk.bvh", frames])
    assert [name for name, _ in sent.files] == [
        "walk.bvh",
        "frames/000001.json",
        "frames/000002.json",
    ]
    assert sent.size_bytes == 9 + 2 + 4
    sent.unpack(tmp_path / "elsewhere")
    assert (tmp_path / "elsewhere" / "frames" / "000002.json").read_bytes() == b"{}{}"
    back = pack_tree(tmp_path / "elsewhere", ["frames", "missing"])
    assert [name for name, _ in back.files] == ["frames/000001.json", "frames/000002.json"]


@pytest.mark.parametrize("name", ["../outside", "/etc/passwd", "runs/../../x", ""])
def test_a_path_that_leaves_the_folder_is_refused(tmp_path: Path, name: str) -> None:
    with pytest.raises(InputError, match="relative path inside the folder"):
        SentFiles(((name, b"x"),)).unpack(tmp_path / "inbox")
    assert not (tmp_path / "outside").exists()


def test_a_worker_sees_a_file_only_with_its_size_and_time(tmp_path: Path) -> None:
    sample = tmp_path / "walk.bvh"
    sample.write_bytes(b"HIERARCHY")
    status = sample.stat()
    token = tmp_path / ".probe"
    token.write_bytes(b"")
    assert sees(str(sample), status.st_size, status.st_mtime_ns, str(token))
    assert not sees(str(sample), status.st_size + 1, status.st_mtime_ns, None)
    assert not sees(str(tmp_path / "gone.bvh"), 9, status.st_mtime_ns, None)
    assert not sees(str(sample), status.st_size, status.st_mtime_ns, str(tmp_path / "nope"))
