"""TRC reader and writer on the Pose2Sim files and on edited copies of them."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.errors import ParseError
from mocapqa.io.trc import format_trc, parse_trc, read_trc, write_trc

POSE3D = "keypoints/pose2sim/*/pose-3d/*.trc"
FIRST_21 = [
    "RHip",
    "RKnee",
    "RAnkle",
    "RBigToe",
    "RSmallToe",
    "RHeel",
    "LHip",
    "LKnee",
    "LAnkle",
    "LBigToe",
    "LSmallToe",
    "LHeel",
    "Neck",
    "Head",
    "Nose",
    "RShoulder",
    "RElbow",
    "RWrist",
    "LShoulder",
    "LElbow",
    "LWrist",
]


def _trc_files(corpus_dir: Path) -> list[Path]:
    files = sorted(corpus_dir.glob(POSE3D))
    assert len(files) == 6
    return files


def test_every_pose2sim_trc_matches_the_data_readme(corpus_dir: Path) -> None:
    for path in _trc_files(corpus_dir):
        seq = read_trc(path)
        expected_frames = 12 if "StaticTrial" in path.name else 100
        expected_markers = 64 if path.name.endswith("_LSTM.trc") else 21
        assert seq.n_frames == expected_frames, path.name
        assert seq.n_keypoints == expected_markers, path.name
        assert seq.names[:21] == tuple(FIRST_21)
        assert seq.fps == 60.0
        assert seq.length_unit == "m"
        assert seq.missing_fraction == 0.0
        assert seq.source_format == "trc"
        assert np.all(seq.confidence == 1.0)
        if expected_markers == 64:
            assert all(name.endswith("_study") for name in seq.names[21:])


def test_first_value_matches_the_file_text(corpus_dir: Path) -> None:
    path = next(
        p for p in _trc_files(corpus_dir) if p.name == "S00_P00_T01_BalancingTrial_0-100.trc"
    )
    row = path.read_text().splitlines()[5].split("\t")
    seq = read_trc(path)
    assert seq.positions[0, 0, 0] == float(row[2])
    assert seq.positions[0, 20, 2] == float(row[2 + 3 * 20 + 2])


def test_floor_is_near_zero_and_y_is_up(corpus_dir: Path) -> None:
    seq = read_trc(_trc_files(corpus_dir)[0])
    heels = [seq.names.index("RHeel"), seq.names.index("LHeel")]
    head = seq.names.index("Head")
    assert abs(float(np.median(seq.positions[:, heels, 1]))) < 0.15
    assert 1.3 < float(np.median(seq.positions[:, head, 1])) < 1.9


def test_written_trc_reads_back_exactly(corpus_dir: Path, tmp_path: Path) -> None:
    for path in _trc_files(corpus_dir):
        seq = read_trc(path)
        write_trc(tmp_path / "out.trc", seq)
        again = read_trc(tmp_path / "out.trc")
        assert again.names == seq.names
        assert again.fps == seq.fps
        assert again.length_unit == seq.length_unit
        np.testing.assert_array_equal(again.positions, seq.positions)


def _edited(corpus_dir: Path) -> list[str]:
    path = (
        corpus_dir
        / "keypoints/pose2sim/S00_P00_T00_StaticTrial/pose-3d/S00_P00_T00_StaticTrial_0-12.trc"
    )
    return path.read_text().splitlines()


def test_empty_cells_are_missing_not_zero(corpus_dir: Path) -> None:
    lines = _edited(corpus_dir)
    cells = lines[6].split("\t")
    cells[2:5] = ["", "", ""]
    lines[6] = "\t".join(cells)
    seq = parse_trc("\n".join(lines), "edited.trc")
    assert np.all(np.isnan(seq.positions[1, 0]))
    assert seq.confidence[1, 0] == 0.0
    assert seq.missing.sum() == 1
    again = parse_trc(format_trc(seq))
    np.testing.assert_array_equal(again.positions, seq.positions)


@pytest.mark.parametrize(("unit", "expected"), [("mm", "mm"), ("cm", "cm"), ("meters", "m")])
def test_units_come_from_the_header(corpus_dir: Path, unit: str, expected: str) -> None:
    lines = _edited(corpus_dir)
    lines[2] = lines[2].replace("\tm\t", f"\t{unit}\t")
    assert parse_trc("\n".join(lines)).length_unit == expected


def test_crlf_and_blank_line_before_data_are_accepted(corpus_dir: Path) -> None:
    lines = _edited(corpus_dir)
    lines.insert(5, "")
    seq = parse_trc("\r\n".join(lines))
    assert seq.n_frames == 12


def test_unknown_unit_names_the_field(corpus_dir: Path) -> None:
    lines = _edited(corpus_dir)
    lines[2] = lines[2].replace("\tm\t", "\tfurlongs\t")
    with pytest.raises(ParseError, match=r"x\.trc, line 3, field 'Units': Expected Units"):
        parse_trc("\n".join(lines), "x.trc")


def test_short_row_names_its_line(corpus_dir: Path) -> None:
    lines = _edited(corpus_dir)
    lines[9] = "\t".join(lines[9].split("\t")[:-4])
    with pytest.raises(ParseError, match=r"line 10: Expected 65 cells"):
        parse_trc("\n".join(lines), "x.trc")


def test_text_in_a_cell_names_its_line(corpus_dir: Path) -> None:
    lines = _edited(corpus_dir)
    lines[7] = lines[7].replace("\t", "\tabc", 3).replace("\tabc", "\t", 2)
    with pytest.raises(ParseError, match=r"line 8: Expected a number, got 'abc"):
        parse_trc("\n".join(lines), "x.trc")


def test_truncated_file_reports_the_frame_count(corpus_dir: Path) -> None:
    lines = _edited(corpus_dir)[:-3]
    with pytest.raises(ParseError, match=r"Expected 12 data rows \(NumFrames\), got 9"):
        parse_trc("\n".join(lines), "x.trc")


def test_infinity_is_rejected(corpus_dir: Path) -> None:
    lines = _edited(corpus_dir)
    cells = lines[5].split("\t")
    cells[3] = "inf"
    lines[5] = "\t".join(cells)
    with pytest.raises(ParseError, match=r"line 6: Expected a finite number"):
        parse_trc("\n".join(lines), "x.trc")


POSE2SIM = "keypoints/pose2sim/S00_P00_T01_BalancingTrial"
TAKES = {
    "openpose": f"{POSE2SIM}/pose/cam01_json",
    "pose2sim trc": f"{POSE2SIM}/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc",
    "mediapipe csv": "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv",
    "mediapipe pbtxt": "keypoints/mediapipe/google_mediapipe_testdata/pose_landmarks.pbtxt",
}


def _frame_column(path: Path) -> list[int]:
    rows = path.read_text(encoding="utf-8").splitlines()[6:]
    return [int(row.split("\t")[0]) for row in rows]


@pytest.mark.parametrize("take", sorted(TAKES))
def test_every_trc_mocapqa_writes_numbers_its_frames_from_1(
    corpus_dir: Path, tmp_path: Path, take: str
) -> None:
    # OpenSim numbers TRC frames from 1; TRCs converted from OpenPose started at 0 (the
    # OpenPose file numbers), the others at 1.
    source = corpus_dir / TAKES[take]
    converted, filtered = tmp_path / "converted.trc", tmp_path / "filtered.trc"
    fps = [] if take != "mediapipe csv" else ["--fps", "90"]
    assert main(["convert", str(source), "-o", str(converted), *fps]) == 0
    assert main(["filter", str(source), "-o", str(filtered), *fps]) == 0
    for path in (converted, filtered):
        frames = _frame_column(path)
        assert frames == list(range(1, len(frames) + 1)), (path.name, frames[:3])
        assert read_trc(path).frame_numbers is not None


def test_trc_frame_numbers_keep_their_spacing_from_1(corpus_dir: Path) -> None:
    seq = read_trc(corpus_dir / TAKES["pose2sim trc"])
    sparse = replace(seq, frame_numbers=np.arange(seq.n_frames) * 2 + 40)
    frames = [int(r.split("\t")[0]) for r in format_trc(sparse).splitlines()[6:]]
    assert frames[:3] == [1, 3, 5]
    zero_based = replace(seq, frame_numbers=np.arange(seq.n_frames), start_frame=None)
    text = format_trc(zero_based).splitlines()
    assert [int(r.split("\t")[0]) for r in text[6:9]] == [1, 2, 3]
    # OrigDataStartFrame keeps the source's first frame number (0 for OpenPose, as Pose2Sim).
    assert text[2].split("\t")[6] == "0"
