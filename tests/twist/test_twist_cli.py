"""``mocapqa refine`` and ``mocapqa detect`` on real takes."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import write_bvh
from mocapqa.twist.inject import inject_twist_errors


def test_refine_writes_the_same_layout_and_a_report(
    takes: dict[str, Motion], tmp_path: Path
) -> None:
    motion = takes["bandai"]
    corrupted, truth = inject_twist_errors(motion, np.random.default_rng(3))
    source = tmp_path / "corrupted.bvh"
    write_bvh(source, corrupted)
    out = tmp_path / "refined.bvh"
    report = tmp_path / "report.json"
    assert main(["refine", str(source), "-o", str(out), "--report", str(report)]) == 0
    written = read_bvh(out)
    original = read_bvh(source)
    assert written.skeleton.names == original.skeleton.names
    assert written.skeleton.channels == original.skeleton.channels
    assert np.array_equal(written.skeleton.parents, original.skeleton.parents)
    assert written.n_frames == original.n_frames
    assert abs(written.frame_time_s - original.frame_time_s) < 1e-9
    data = json.loads(report.read_text())
    assert {i["joint"] for i in data["intervals"]} == {i.joint for i in truth.intervals}
    assert {"start_frame", "end_frame", "offset_deg", "confidence"} <= set(data["intervals"][0])
    assert len(data["joints"]) == 10
    # Continuous Euler angles: no more channel jumps above 180° than the clean take has
    # (Bandai files wrap their angles to ±180° themselves).
    clean = tmp_path / "clean.bvh"
    write_bvh(clean, motion)
    assert _wrap_jumps(out) <= _wrap_jumps(clean)


def _wrap_jumps(path: Path) -> int:
    lines = path.read_text().split("MOTION")[1].splitlines()[3:]
    values = np.array([[float(v) for v in line.split()] for line in lines if line.strip()])
    return int(np.sum(np.abs(np.diff(values, axis=0)) > 180.0))


def test_detect_prints_json_without_writing(
    takes: dict[str, Motion], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    corrupted, truth = inject_twist_errors(takes["cmu"], np.random.default_rng(6))
    source = tmp_path / "take.bvh"
    write_bvh(source, corrupted)
    assert main(["detect", str(source), "--json"]) == 0
    out = capsys.readouterr().out
    data = json.loads(out)
    assert {i["joint"] for i in data["intervals"]} == {i.joint for i in truth.intervals}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["take.bvh"]
    assert main(["detect", str(source), "--method", "nope"]) == 3


def test_bench_twist_prints_both_tables_for_each_method(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "bandai").mkdir()
    for name in ("dataset-2_walk_normal_001.bvh", "dataset-1_bow_sad_001.bvh"):
        shutil.copy(corpus_dir / "bvh" / "bandai" / name, tmp_path / "bandai" / name)
    assert main(["bench", "twist", "--data", str(tmp_path), "--repeats", "1"]) == 0
    out = capsys.readouterr().out
    assert "Table 1" in out
    assert "Table 2 (robust)" in out
    assert "Table 2 (paper)" in out
    assert "held-out" in out
    # The unpaired-burst row: both takes are long enough, one injection each.
    unpaired = out[out.index("Unpaired bursts after a natural roll step") :]
    rows = {line.split("│")[1].strip(): line.split("│")[2:] for line in unpaired.splitlines()
            if line.startswith("│")}  # fmt: skip
    assert rows["all"][0].strip() == "2"
    assert rows["all: fit set"][0].strip() == rows["all: held-out"][0].strip() == "1"
    assert main(["bench", "twist", "--data", str(tmp_path / "bandai" / "none")]) == 3
