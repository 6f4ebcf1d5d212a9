"""Output files are written whole or not at all, and never replace a device, FIFO or folder.

No test writes to ``/dev/null`` or ``/dev/full``: the machine is shared (a broken writer once
replaced them). A FIFO and a folder in ``tmp_path`` stand for "not a regular file".
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError
from mocapqa.io.atomic import PendingFile, atomic_path, output_target, write_bytes, write_text
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import write_bvh
from mocapqa.io.formats import KEYPOINT_WRITE_FORMATS, read_take, write_keypoints
from mocapqa.io.keypoint_csv import csv_sidecar_path


def _sequence() -> KeypointSequence:
    rng = np.random.default_rng(0)
    positions = rng.normal(size=(5, 3, 3))
    return KeypointSequence(
        positions=positions,
        confidence=np.ones((5, 3)),
        names=("a", "b", "c"),
        fps=30.0,
        length_unit="m",
    )


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))


def test_write_replaces_the_file_and_leaves_no_temporary(tmp_path: Path) -> None:
    out = tmp_path / "out.txt"
    out.write_text("old", encoding="utf-8")
    write_text(out, "new\n")
    assert out.read_text(encoding="utf-8") == "new\n"
    write_bytes(tmp_path / "fresh.bin", b"\x00\x01")
    assert (tmp_path / "fresh.bin").read_bytes() == b"\x00\x01"
    assert _leftovers(tmp_path) == []


def _write_then_fail(out: Path, error: Exception) -> None:
    with atomic_path(out) as temporary:
        temporary.write_text("half a rep", encoding="utf-8")
        raise error


def test_a_failed_write_keeps_the_old_file_and_removes_the_temporary(tmp_path: Path) -> None:
    out = tmp_path / "out.html"
    out.write_text("the good report", encoding="utf-8")
    with pytest.raises(RuntimeError, match="renderer crashed"):
        _write_then_fail(out, RuntimeError("renderer crashed"))
    assert out.read_text(encoding="utf-8") == "the good report"
    assert _leftovers(tmp_path) == []


def test_a_full_disk_names_the_output_not_the_temporary(tmp_path: Path) -> None:
    """An OSError while writing (here EFBIG, as under ``ulimit -f``) is raised again with the
    output's path, so the CLI's one-line message names it."""
    out = tmp_path / "out.png"
    out.write_bytes(b"good png")
    with pytest.raises(OSError, match="File too large") as caught:
        _write_then_fail(out, OSError(errno.EFBIG, "File too large"))
    assert caught.value.errno == errno.EFBIG
    assert caught.value.filename == str(out)
    assert out.read_bytes() == b"good png"
    assert _leftovers(tmp_path) == []


def test_an_output_in_a_missing_folder_names_the_output(tmp_path: Path) -> None:
    out = tmp_path / "missing" / "out.bvh"
    with pytest.raises(FileNotFoundError) as caught:
        write_text(out, "x")
    assert caught.value.filename == str(out)


@pytest.mark.parametrize("kind", ["fifo", "directory"])
def test_a_target_that_is_not_a_regular_file_is_refused(tmp_path: Path, kind: str) -> None:
    target = tmp_path / f"{kind}.bvh"
    if kind == "fifo":
        os.mkfifo(target)
    else:
        target.mkdir()
    with pytest.raises(InputError, match=rf"got a {'FIFO' if kind == 'fifo' else 'directory'}"):
        write_text(target, "x")
    mode = target.lstat().st_mode
    assert stat.S_ISFIFO(mode) if kind == "fifo" else stat.S_ISDIR(mode)
    with pytest.raises(InputError) as caught:
        output_target(target)
    assert str(target) in str(caught.value)
    assert _leftovers(tmp_path) == []


def test_a_symlink_is_written_through_and_kept(tmp_path: Path) -> None:
    real = tmp_path / "real.bvh"
    real.write_text("old", encoding="utf-8")
    link = tmp_path / "link.bvh"
    link.symlink_to(real.name)
    write_text(link, "new")
    assert link.is_symlink()
    assert os.readlink(link) == real.name
    assert real.read_text(encoding="utf-8") == "new"
    # A dangling link creates the file it names.
    dangling = tmp_path / "dangling.bvh"
    dangling.symlink_to("created.bvh")
    write_text(dangling, "made")
    assert dangling.is_symlink()
    assert (tmp_path / "created.bvh").read_text(encoding="utf-8") == "made"
    assert _leftovers(tmp_path) == []


def test_a_symlink_to_a_fifo_is_refused_naming_the_link(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    link = tmp_path / "out.bvh"
    link.symlink_to(fifo)
    with pytest.raises(InputError, match="FIFO") as caught:
        write_text(link, "x")
    assert str(link) in str(caught.value)
    assert str(fifo) in str(caught.value)
    assert stat.S_ISFIFO(fifo.lstat().st_mode)


def test_the_replaced_file_keeps_its_permissions(tmp_path: Path) -> None:
    out = tmp_path / "out.bvh"
    out.write_text("old", encoding="utf-8")
    out.chmod(0o640)
    write_text(out, "new")
    assert stat.S_IMODE(out.stat().st_mode) == 0o640
    fresh = tmp_path / "fresh.bvh"
    write_text(fresh, "new")
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o666 & ~umask


def test_a_pending_file_is_committed_or_discarded(tmp_path: Path) -> None:
    out = tmp_path / "table.csv"
    out.write_text("old table", encoding="utf-8")
    pending = PendingFile(out)
    pending.temporary.write_text("half", encoding="utf-8")
    pending.discard()
    assert out.read_text(encoding="utf-8") == "old table"
    pending = PendingFile(out)
    pending.temporary.write_text("new table", encoding="utf-8")
    pending.commit()
    assert out.read_text(encoding="utf-8") == "new table"
    assert _leftovers(tmp_path) == []


def _write(kind: str, path: Path, walk: Path) -> None:
    if kind == "bvh":
        write_bvh(path, read_bvh(walk))
    else:
        write_keypoints(path, _sequence())


@pytest.mark.parametrize("kind", ["bvh", *KEYPOINT_WRITE_FORMATS])
def test_every_take_writer_refuses_a_fifo_and_writes_through_a_link(
    tmp_path: Path, cmu_walk: Path, kind: str
) -> None:
    fifo = tmp_path / f"pipe.{kind}"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="FIFO"):
        _write(kind, fifo, cmu_walk)
    assert stat.S_ISFIFO(fifo.lstat().st_mode)
    real = tmp_path / f"real.{kind}"
    link = tmp_path / f"link.{kind}"
    link.symlink_to(real.name)
    _write(kind, link, cmu_walk)
    assert link.is_symlink()
    assert real.is_file()
    assert read_take(link, fps=30.0).n_frames == (524 if kind == "bvh" else 5)
    assert _leftovers(tmp_path) == []


def test_a_keypoint_csv_and_its_sidecar_are_kept_together_on_failure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "kp.csv"
    write_keypoints(out, _sequence())
    table, meta = out.read_bytes(), csv_sidecar_path(out).read_bytes()

    def broken(seq: object) -> dict[str, object]:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("mocapqa.io.keypoint_csv.csv_sidecar", broken)
    with pytest.raises(OSError, match="No space left") as caught:
        write_keypoints(out, _sequence())
    assert caught.value.filename is not None
    assert out.read_bytes() == table
    assert csv_sidecar_path(out).read_bytes() == meta
    assert _leftovers(tmp_path) == []
