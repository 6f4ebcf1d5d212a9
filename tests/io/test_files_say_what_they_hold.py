"""Output files that other tools read as they are, and inputs whose gaps and rates are kept.

* the long CSV of ``mocapqa filter``/``convert`` reads with ``pandas.read_csv`` and
  ``csv.DictReader`` and no options; its fps and unit are in the ``.meta.json`` sidecar; files
  with the older ``# fps`` comment lines still read;
* a frame rate estimated from a rounded time column snaps to the standard rate, and says so;
* an OpenPose folder whose frame numbers skip keeps the gaps as missing frames;
* ``filter`` on a 5-frame take prints no numpy warning;
* every TRC the project writes loads in OpenSim 4.6 (the ``opensim`` wheel from PyPI), keeps
  every cell of every row, and keeps the source's frame numbers, times and start frame.
"""

from __future__ import annotations

import csv
import shutil
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import opensim
import pandas as pd
import pytest

from mocapqa.cli.main import main
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import write_bvh
from mocapqa.io.formats import read_take
from mocapqa.io.keypoint_csv import csv_sidecar_path, parse_keypoint_csv
from mocapqa.io.openpose import read_openpose
from mocapqa.io.trc import format_trc, read_trc

POSE2SIM = "keypoints/pose2sim/S00_P00_T01_BalancingTrial"
OPENPOSE = f"{POSE2SIM}/pose/cam01_json"
TRC = f"{POSE2SIM}/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


def test_the_filtered_csv_reads_with_pandas_and_dictreader(
    corpus_dir: Path, tmp_path: Path
) -> None:
    out = tmp_path / "filtered.csv"
    assert main(["filter", str(corpus_dir / OPENPOSE), "-o", str(out)]) == 0
    frame = pd.read_csv(out)
    assert list(frame.columns) == ["frame", "time", "keypoint", "x", "y", "confidence"]
    with out.open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == len(frame) == 100 * 25
    assert rows[0]["keypoint"] == "Nose"
    assert rows[0]["frame"] == "0"
    assert frame["time"].iloc[-1] == pytest.approx(99 / 30)
    sidecar = csv_sidecar_path(out)
    assert sidecar.name == "filtered.csv.meta.json"
    back = read_take(out)
    assert isinstance(back, KeypointSequence)
    assert (back.fps, back.length_unit) == (30.0, "px")
    # Without the sidecar the time column still gives the rate, the unit is unknown.
    sidecar.unlink()
    alone = read_take(out)
    assert isinstance(alone, KeypointSequence)
    assert alone.fps == 30.0
    assert alone.length_unit == "unknown"


def test_csv_with_the_older_comment_lines_still_reads() -> None:
    text = "# fps: 50\n# unit: mm\nframe,keypoint,x,y,z\n0,a,1,2,3\n1,a,1,2,4\n"
    seq = parse_keypoint_csv(text, "old.csv")
    assert (seq.fps, seq.length_unit) == (50.0, "mm")
    assert seq.positions[1, 0, 2] == 4.0


@pytest.mark.parametrize(
    ("rate", "digits", "expected"),
    [(30.0, 4, 30.0), (60.0, 3, 60.0), (30000 / 1001, 5, 30000 / 1001), (37.0, 6, None)],
)
def test_a_rate_estimated_from_rounded_times_snaps_to_the_standard(
    rate: float, digits: int, expected: float | None
) -> None:
    rows = [f"{f},{round(f / rate, digits)},a,0,0,0" for f in range(120)]
    seq = parse_keypoint_csv("frame,time,keypoint,x,y,z\n" + "\n".join(rows), "t.csv")
    if expected is None:
        assert seq.fps == pytest.approx(rate, rel=1e-4)
        assert "no standard rate within 0.02 %" in seq.assumptions[0]
    else:
        assert seq.fps == expected
        assert "snapped to the standard" in seq.assumptions[0]


def test_openpose_frame_numbers_keep_their_gaps(corpus_dir: Path, tmp_path: Path) -> None:
    source = sorted((corpus_dir / OPENPOSE).glob("*.json"))
    for number in (0, 1, 2, 3, 9):
        shutil.copy(source[number], tmp_path / source[number].name)
    seq = read_openpose(tmp_path)
    full = read_openpose(corpus_dir / OPENPOSE)
    assert seq.n_frames == 10
    assert seq.frame_numbers is not None
    assert seq.frame_numbers.tolist() == list(range(10))
    assert np.all(np.isnan(seq.positions[4:9]))
    np.testing.assert_array_equal(seq.positions[[0, 1, 2, 3, 9]], full.positions[[0, 1, 2, 3, 9]])
    assert any("skip 5 frame(s)" in a for a in seq.assumptions)


def five_frame_takes(corpus_dir: Path, folder: Path) -> list[Path]:
    ops = folder / "op5"
    ops.mkdir()
    for path in sorted((corpus_dir / OPENPOSE).glob("*.json"))[:5]:
        shutil.copy(path, ops / path.name)
    trc = read_trc(corpus_dir / TRC)
    short = replace(
        trc, positions=trc.positions[:5], confidence=trc.confidence[:5],
        frame_numbers=trc.frame_numbers[:5] if trc.frame_numbers is not None else None,
        times=trc.times[:5] if trc.times is not None else None,
    )  # fmt: skip
    (folder / "five.trc").write_text(format_trc(short), encoding="utf-8")
    walk = read_bvh(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    write_bvh(
        folder / "five.bvh",
        replace(
            walk,
            quats=walk.quats[:5],
            translations=walk.translations[:5],
            euler_hint_deg=None if walk.euler_hint_deg is None else walk.euler_hint_deg[:5],
        ),
    )
    return [ops, folder / "five.trc", folder / "five.bvh"]


def test_filter_on_a_five_frame_take_prints_no_numpy_warning(
    corpus_dir: Path, tmp_path: Path
) -> None:
    for take in five_frame_takes(corpus_dir, tmp_path):
        suffix = ".bvh" if take.suffix == ".bvh" else ".csv"
        for method in [] if suffix == ".bvh" else ["adaptive", "one-euro", "kalman", "ema"]:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                out = tmp_path / f"out_{take.stem}_{method}{suffix}"
                report = tmp_path / "report.json"
                assert main(["filter", str(take), "-o", str(out), "--method", method,
                             "--report", str(report)]) == 0  # fmt: skip
            assert [str(w.message) for w in caught] == [], (take, method)
        if suffix == ".bvh":
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                assert main(["filter", str(take), "-o", str(tmp_path / "f.bvh")]) == 0
            assert [str(w.message) for w in caught] == []


def opensim_rows(path: Path) -> tuple[int, int, list[float], dict[str, str]]:
    table = opensim.TimeSeriesTableVec3(str(path))
    meta = {k: table.getTableMetaDataAsString(k) for k in table.getTableMetaDataKeys()}
    return table.getNumRows(), table.getNumColumns(), list(table.getIndependentColumn()), meta


def test_every_trc_the_project_writes_loads_in_opensim(corpus_dir: Path, tmp_path: Path) -> None:
    # convert of the OpenPose folder (missing markers on rows, trailing ones included), of the
    # Pose2Sim TRC, and filter to TRC: OpenSim 4.6 refused the first ("Unexpected number of
    # columns") when missing cells were written empty.
    outputs = {
        "openpose": (["convert", str(corpus_dir / OPENPOSE)], tmp_path / "openpose.trc"),
        "pose2sim": (["convert", str(corpus_dir / TRC)], tmp_path / "pose2sim.trc"),
        "filtered": (["filter", str(corpus_dir / TRC)], tmp_path / "filtered.trc"),
    }
    for args, out in outputs.values():
        assert main([*args, "-o", str(out)]) == 0
        width = None
        for line in out.read_text(encoding="utf-8").splitlines()[6:]:
            cells = line.split("\t")
            width = width or len(cells)
            assert len(cells) == width, line[:80]
            assert all(c.strip() for c in cells), line[:80]
    n_rows, n_markers, times, meta = opensim_rows(outputs["openpose"][1])
    assert (n_rows, n_markers) == (100, 25)
    assert meta["Units"] == "px"
    assert meta["OrigDataStartFrame"] == "0"
    # The Pose2Sim TRC keeps its frame numbers (from 1), times (from 1/60 s) and start frame.
    for name in ("pose2sim", "filtered"):
        n_rows, n_markers, times, meta = opensim_rows(outputs[name][1])
        assert (n_rows, n_markers) == (100, 21)
        assert times[0] == pytest.approx(1 / 60)
        assert times[-1] == pytest.approx(100 / 60)
        assert meta["OrigDataStartFrame"] == "0"
        assert meta["DataRate"] == "60.0"
    source = (corpus_dir / TRC).read_text(encoding="utf-8").splitlines()
    written = outputs["pose2sim"][1].read_text(encoding="utf-8").splitlines()
    assert [r.split("\t")[:2] for r in written[6:]] == [r.split("\t")[:2] for r in source[5:]]


def test_a_copy_with_other_frames_drops_the_source_numbering(corpus_dir: Path) -> None:
    trc = read_trc(corpus_dir / TRC)
    assert trc.frame_numbers is not None
    assert trc.frame_numbers[0] == 1
    assert trc.times is not None
    assert trc.times[0] == pytest.approx(1 / 60)
    assert trc.start_frame == 0
    same = replace(trc, positions=trc.positions + 1.0)
    assert same.frame_numbers is not None
    assert same.times is not None
    cut = replace(trc, positions=trc.positions[:5], confidence=trc.confidence[:5])
    assert cut.frame_numbers is None
    assert cut.times is None
