"""Writers round-trip through their readers; the CSV, JSON and NumPy readers' own rules."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.formats import read_take, write_keypoints
from mocapqa.io.keypoint_arrays import parse_keypoint_npy
from mocapqa.io.keypoint_csv import parse_keypoint_csv
from mocapqa.io.keypoint_json import parse_keypoint_json
from mocapqa.io.openpose import read_openpose
from mocapqa.io.trc import read_trc

TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
OPENPOSE = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-associated/cam01_json"


def _with_gaps(seq: KeypointSequence, seed: int) -> KeypointSequence:
    rng = np.random.default_rng(seed)
    positions = seq.positions.copy()
    confidence = rng.uniform(0.05, 1.0, seq.confidence.shape)
    positions[rng.random(seq.confidence.shape) < 0.05] = np.nan
    return KeypointSequence(
        seq.names, positions, confidence, seq.fps, seq.length_unit, seq.n_dims, seq.source_format
    )


def _assert_same(a: KeypointSequence, b: KeypointSequence, *, confidence: bool = True) -> None:
    assert a.names == b.names
    assert a.fps == b.fps
    assert a.n_dims == b.n_dims
    assert a.length_unit == b.length_unit
    np.testing.assert_array_equal(a.positions, b.positions)
    if confidence:
        np.testing.assert_array_equal(a.confidence, b.confidence)


@pytest.mark.parametrize("suffix", ["csv", "json", "npz"])
def test_lossless_writers_round_trip_3d_and_2d(
    corpus_dir: Path, tmp_path: Path, suffix: str
) -> None:
    for seq in (
        _with_gaps(read_trc(corpus_dir / TRC), seed=1),
        read_openpose(corpus_dir / OPENPOSE, fps=60),
    ):
        write_keypoints(tmp_path / f"out.{suffix}", seq)
        again = read_take(tmp_path / f"out.{suffix}")
        assert isinstance(again, KeypointSequence)
        _assert_same(seq, again)
        assert again.missing.sum() == seq.missing.sum() > 0


def test_npy_round_trip_keeps_positions_and_confidence(corpus_dir: Path, tmp_path: Path) -> None:
    seq = _with_gaps(read_trc(corpus_dir / TRC), seed=2)
    write_keypoints(tmp_path / "out.npy", seq)
    again = read_take(tmp_path / "out.npy", fps=60, length_unit="m")
    assert isinstance(again, KeypointSequence)
    np.testing.assert_array_equal(again.positions, seq.positions)
    np.testing.assert_array_equal(again.confidence, seq.confidence)
    assert again.names[0] == "keypoint_0"


def test_trc_round_trip_keeps_gaps(corpus_dir: Path, tmp_path: Path) -> None:
    seq = _with_gaps(read_trc(corpus_dir / TRC), seed=3)
    write_keypoints(tmp_path / "out.trc", seq)
    again = read_take(tmp_path / "out.trc")
    assert isinstance(again, KeypointSequence)
    _assert_same(seq, again, confidence=False)


def test_csv_time_column_gives_fps_and_2d_without_z() -> None:
    text = "frame,time,keypoint,x,y\n0,0.0,a,1,2\n0,0.0,b,3,\n1,0.04,a,5,6\n1,0.04,b,7,8\n"
    seq = parse_keypoint_csv(text)
    assert seq.fps == pytest.approx(25.0)
    assert seq.n_dims == 2
    assert seq.length_unit == "unknown"
    assert seq.missing.tolist() == [[False, True], [False, False]]
    assert seq.positions[1, 1].tolist() == [7.0, 8.0, 0.0]
    assert seq.confidence.tolist() == [[1.0, 0.0], [1.0, 1.0]]


def test_csv_without_time_needs_fps() -> None:
    text = "frame,keypoint,x,y,z\n0,a,1,2,3\n"
    with pytest.raises(ParseError, match="needs the fps argument"):
        parse_keypoint_csv(text, "k.csv")
    assert parse_keypoint_csv(text, fps=50, length_unit="mm").length_unit == "mm"


def test_csv_duplicate_row_names_its_line() -> None:
    text = "frame,keypoint,x,y,z\n0,a,1,2,3\n0,a,1,2,3\n"
    with pytest.raises(ParseError, match="line 3: Expected one row per frame and keypoint"):
        parse_keypoint_csv(text, "k.csv", fps=30)


def test_json_null_is_missing_and_fps_is_required() -> None:
    text = '{"keypoints": ["a", "b"], "frames": [[[1, 2, 3, 0.5], null]]}'
    with pytest.raises(ParseError, match="field 'fps'"):
        parse_keypoint_json(text, "k.json")
    seq = parse_keypoint_json(text, fps=10)
    assert seq.missing.tolist() == [[False, True]]
    assert seq.confidence[0, 0] == 0.5


def test_json_bad_point_names_the_field() -> None:
    text = '{"fps": 30, "keypoints": ["a"], "frames": [[[1, "x", 3]]]}'
    with pytest.raises(ParseError, match=r"field 'frames\[0\]\[0\]\[1\]'"):
        parse_keypoint_json(text, "k.json")


def test_npy_wrong_shape_and_garbage_are_parse_errors(tmp_path: Path) -> None:
    np.save(tmp_path / "flat.npy", np.zeros((4, 3)))
    with pytest.raises(ParseError, match=r"Expected an array of shape \(F, K, 2\|3\|4\)"):
        parse_keypoint_npy((tmp_path / "flat.npy").read_bytes(), "flat.npy", fps=30)
    with pytest.raises(ParseError, match="Expected a NumPy array header"):
        parse_keypoint_npy(b"\x93NUMPY garbage", "bad.npy", fps=30)


@pytest.mark.parametrize("dtype", [np.complex128, np.bool_])
def test_npy_of_no_real_numbers_is_refused_naming_the_dtype(dtype: type) -> None:
    import io

    buffer = io.BytesIO()
    np.save(buffer, np.ones((4, 2, 3), dtype=dtype), allow_pickle=False)
    with pytest.raises(ParseError, match="real numbers, got dtype"):
        parse_keypoint_npy(buffer.getvalue(), "odd.npy", fps=30.0)


def test_a_csv_with_a_byte_order_mark_reads_as_without_one() -> None:
    # Spreadsheets save UTF-8 CSVs with a BOM; decoded elsewhere first, it stayed on "frame".
    text = "\ufeffframe,keypoint,x,y,z\n0,a,1,2,3\n1,a,1,2,3\n"
    for data in (text, text.encode("utf-8")):
        assert parse_keypoint_csv(data, "bom.csv", fps=30.0).n_frames == 2


def test_truncated_headers_say_what_is_missing() -> None:
    from mocapqa.io.bvh import parse_bvh
    from mocapqa.io.trc import parse_trc

    with pytest.raises(ParseError, match="'HIERARCHY' section before 'MOTION', got 'MOTION' first"):
        parse_bvh("MOTION\nFrames: 1\nFrame Time: 0.033\n0 0 0\n", "x.bvh")
    # It said "Expected a TRC file starting 'PathFileType', got 'PathFileType...'".
    with pytest.raises(ParseError, match="TRC header of 3 lines and a marker row, got 1 line"):
        parse_trc("PathFileType\t4\t(X/Y/Z)\tx.trc\n", "x.trc")


def test_json_round_trip_keeps_the_start_time(corpus_dir: Path, tmp_path: Path) -> None:
    # The Pose2Sim TRC starts at 1/60 s; its keypoint JSON read back started at 0.
    source = read_trc(corpus_dir / TRC)
    assert source.times is not None
    assert source.times[0] == pytest.approx(0.016667, abs=1e-6)
    path = tmp_path / "take.json"
    assert main(["convert", str(corpus_dir / TRC), "-o", str(path)]) == 0
    back = read_take(path)
    assert isinstance(back, KeypointSequence)
    assert back.times is not None
    np.testing.assert_array_equal(back.times, source.times)
    # On to TRC again: the time column is the source's.
    assert main(["convert", str(path), "-o", str(tmp_path / "again.trc")]) == 0
    again = read_trc(tmp_path / "again.trc")
    assert again.times is not None
    np.testing.assert_array_equal(again.times, source.times)


def test_json_without_times_starts_at_0_and_bad_times_name_the_field() -> None:
    head = '{"fps": 10, "keypoints": ["a"], "frames": [[[1, 2, 3]], [[1, 2, 4]]]'
    assert parse_keypoint_json(head + "}").times is None
    seq = parse_keypoint_json(head + ', "times": [0.5, 0.6]}')
    assert seq.times is not None
    assert seq.times.tolist() == [0.5, 0.6]
    for times in ("[0.5]", '[0.5, "x"]', '"0.5"', "[0.5, true]", "[0.5, 1e999]"):
        with pytest.raises(ParseError, match="field 'times"):
            parse_keypoint_json(head + f', "times": {times}}}', "k.json")
