"""``mocapqa batch`` says which takes failed, leaves keypoint CSV sidecars alone, and writes its
results table whole or not at all."""

from __future__ import annotations

import csv
import errno
import json
import os
import re
import shutil
import stat
from pathlib import Path
from typing import Any

import pytest

from mocapqa.cli.batch import MAX_FAILED_LINES
from mocapqa.cli.main import main
from mocapqa.errors import InputError
from mocapqa.jobs.batch import BatchCounts, discover, run_batch
from mocapqa.jobs.batch_output import ResultWriter
from mocapqa.jobs.take_task import analyse_path

TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


def test_discovery_skips_a_keypoint_csv_sidecar(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "takes"
    folder.mkdir()
    assert main(["convert", str(corpus_dir / TRC), "-o", str(folder / "kp.csv")]) == 0
    sidecar = folder / "kp.csv.meta.json"
    assert sidecar.is_file()
    (folder / "take.json").write_text("{}", encoding="utf-8")
    found = list(discover([folder]))
    assert found == [(folder / "kp.csv", None), (folder / "take.json", None)]
    # Named on the command line, it is listed as skipped with the reason.
    [(path, reason)] = list(discover([sidecar]))
    assert path == sidecar
    assert reason is not None
    assert "sidecar" in reason


def _fails_the_bad_takes(
    path: str, options: dict[str, Any], take_id: str, run_id: str, data_dir: str | None
) -> dict[str, Any]:
    """The per-take task of the batch: ``badNN.bvh`` fails with a reason naming line NN; any
    other take is analysed and stored for real."""
    name = Path(path).name
    if name.startswith("bad"):
        return {"status": "failed", "error": f"line {int(name[3:5])}: broken"}
    return analyse_path(path, options, take_id, run_id, data_dir)


def test_without_output_each_failed_take_is_one_stderr_line(
    cmu_walk: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    monkeypatch.setenv("MOCAPQA_DATA_DIR", str(tmp_path / "data"))
    folder = tmp_path / "takes"
    folder.mkdir()
    shutil.copyfile(cmu_walk, folder / "good.bvh")
    for k in range(MAX_FAILED_LINES + 3):  # distinct contents: a copy would be skipped
        (folder / f"bad{k:02d}.bvh").write_text(f"take {k}\n", encoding="utf-8")

    def in_process(*args: Any, **kwargs: Any) -> BatchCounts:
        """The real batch with its per-take task (``task=``) failing the bad takes, run in this
        process (``engine=None``: no local cluster, rows in the order the takes are found)."""
        return run_batch(*args, **{**kwargs, "engine": None, "task": _fails_the_bad_takes})

    monkeypatch.setattr("mocapqa.jobs.batch.run_batch", in_process)
    code = main(["batch", str(folder)])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = [line for line in err.splitlines() if line.startswith("failed: ")]
    assert len(lines) == MAX_FAILED_LINES
    assert lines[0] == f"failed: {folder / 'bad00.bvh'}: line 0: broken"
    assert lines[-1] == f"failed: {folder / 'bad49.bvh'}: line 49: broken"
    assert "… and 3 more failed" in err
    assert "good.bvh" not in err
    assert re.search(r"54 file\(s\): 1 done, 53 failed, 0 skipped; 524 frames", err), err


def test_batch_of_a_folder_with_a_converted_csv_fails_only_the_bad_take(
    corpus_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    """The hostile pass: ``convert kp.trc -o DIR/kp.csv`` then ``batch DIR`` listed the
    sidecar as a failed take, and said only "0 done, 3 failed"."""
    monkeypatch.setenv("MOCAPQA_DATA_DIR", str(tmp_path / "data"))
    folder = tmp_path / "takes"
    folder.mkdir()
    assert main(["convert", str(corpus_dir / TRC), "-o", str(folder / "kp.csv")]) == 0
    broken = folder / "broken.bvh"
    broken.write_text("HIERARCHY\nJOINT Hips\nMOTION\n", encoding="utf-8")
    capsys.readouterr()
    code = main(["batch", str(folder), "--workers", "1"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "2 file(s): 1 done, 1 failed" in err, err
    failed = [line for line in err.splitlines() if line.startswith("failed: ")]
    assert len(failed) == 1, err
    assert failed[0].startswith(f"failed: {broken}: "), err
    assert "Expected 'ROOT'" in failed[0], err
    assert "meta.json" not in err


@pytest.mark.parametrize("suffix", [".csv", ".jsonl", ".parquet"])
def test_the_results_table_is_replaced_whole_or_not_at_all(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, suffix: str
) -> None:
    out = tmp_path / f"results{suffix}"
    out.write_bytes(b"an earlier table")
    with ResultWriter(out) as writer:
        writer.write({"source": "a.bvh", "status": "done", "n_frames": 524})
        assert out.read_bytes() == b"an earlier table"  # rows go to a temporary meanwhile
    assert table_rows(out) == [("a.bvh", "done", 524)]
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]

    # A disk that fills up on the last rows: the earlier table stays, no temporary is left.
    out.write_bytes(b"an earlier table")
    writer = ResultWriter(out)
    writer.write({"source": "a.bvh", "status": "done"})
    writer.flush()
    writer.write({"source": "b.bvh", "status": "done"})
    monkeypatch.setattr(writer, f"_flush_{'parquet' if suffix == '.parquet' else 'text'}", _full)
    with pytest.raises(OSError, match="No space left") as caught:
        writer.close()
    assert caught.value.filename == str(out)
    assert out.read_bytes() == b"an earlier table"
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]


def table_rows(path: Path) -> list[tuple[str, str, int]]:
    """The ``source``, ``status`` and ``n_frames`` of each row of a results table."""
    if path.suffix == ".parquet":
        import pyarrow.parquet as pq

        rows = pq.read_table(path).to_pylist()
    elif path.suffix == ".csv":
        with path.open(newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(handle))
    else:
        rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]
    return [(row["source"], row["status"], int(row["n_frames"])) for row in rows]


def _full() -> None:
    raise OSError(errno.ENOSPC, "No space left on device")


def test_the_results_table_refuses_a_fifo(tmp_path: Path) -> None:
    fifo = tmp_path / "results.csv"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="FIFO"):
        ResultWriter(fifo)
    assert stat.S_ISFIFO(fifo.lstat().st_mode)
