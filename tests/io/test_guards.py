"""The read limits (``io/guards.py``): exact at their boundaries, and a deep rig read,
analysed and written without recursion when the limits allow it."""

from __future__ import annotations

import io
import pickle
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest
from tests.api.test_hostile import bvh_text

from mocapqa.errors import ParseError, TooLargeError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import format_bvh
from mocapqa.io.formats import read_take
from mocapqa.io.guards import (
    ReadLimits,
    check_frame_points,
    check_json_depth,
    check_line_length,
    check_take_input,
)
from mocapqa.io.keypoint_csv import parse_keypoint_csv
from mocapqa.io.mediapipe import parse_mediapipe_csv
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.options import AnalysisOptions


@pytest.mark.parametrize("chunk_edge", [0, 1, (1 << 20) - 3])
def test_line_length_is_exact_across_chunks(tmp_path: Path, chunk_edge: int) -> None:
    path = tmp_path / "lines.csv"
    longest = 2_000_000
    path.write_bytes(b"a" * chunk_edge + b"\n" + b"b" * longest + b"\nshort\n")
    check_line_length(path, longest)
    with pytest.raises(TooLargeError, match=r"line 2: .*max_line_bytes"):
        check_line_length(path, longest - 1)


def test_json_depth_is_exact(tmp_path: Path) -> None:
    path = tmp_path / "deep.json"
    path.write_bytes(b'{"a": [[[1]]], "b": "a [ in a string counts: the estimate refuses"}')
    check_json_depth(path, 4)
    with pytest.raises(TooLargeError, match="max_json_depth"):
        check_json_depth(path, 3)


def test_npz_limits_come_from_the_headers(tmp_path: Path) -> None:
    path = tmp_path / "big.npz"
    buffer = io.BytesIO()
    np.savez_compressed(buffer, positions=np.zeros((1000, 10, 3)), fps=np.float64(30))
    path.write_bytes(buffer.getvalue())
    check_take_input(path, "npz", ReadLimits(max_frame_points=10_000))
    with pytest.raises(TooLargeError, match=r"max_frame_points.* 1000 × 10"):
        check_take_input(path, "npz", ReadLimits(max_frame_points=9_999))
    with pytest.raises(TooLargeError, match="max_unpacked_bytes"):
        check_take_input(path, "npz", ReadLimits(max_unpacked_bytes=200_000))
    assert zipfile.is_zipfile(path)


def test_joint_count_counts_keywords_not_names(tmp_path: Path) -> None:
    path = tmp_path / "names.bvh"
    path.write_text(bvh_text(3, chain=True).replace("j1", "JOINT_ROOT"))
    check_take_input(path, "bvh", ReadLimits(max_joints=3))
    with pytest.raises(TooLargeError, match=r"max_joints.* got 3"):
        check_take_input(path, "bvh", ReadLimits(max_joints=2))


def test_a_999_joint_chain_is_read_analysed_and_written(tmp_path: Path) -> None:
    """Refused by the default limit at upload; read and processed fine when allowed."""
    path = tmp_path / "chain.bvh"
    path.write_text(bvh_text(999, chain=True))
    with pytest.raises(TooLargeError, match="max_joints"):
        read_take(path, limits=ReadLimits())
    motion = read_take(path, limits=ReadLimits(max_joints=1000))
    result = analyze(motion, AnalysisOptions(checks=("twist", "limits")))
    assert result.corrected_motion is not None
    text = format_bvh(result.corrected_motion)
    again = read_bvh(_write(tmp_path / "again.bvh", text))
    assert again.skeleton.n_joints == 999
    assert list(again.skeleton.parents) == [-1, *range(998)]


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


TRC_TAKE = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/" + (
    "S00_P00_T01_BalancingTrial_0-100_filt_butterworth_LSTM.trc"
)
MEDIAPIPE_TAKE = "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv"


@pytest.mark.parametrize("take", [TRC_TAKE, MEDIAPIPE_TAKE])
def test_frame_points_counted_before_parsing_are_exact_on_real_takes(
    corpus_dir: Path, take: str
) -> None:
    """A real TRC (header, labels, a blank line) and a real MediaPipe CSV: the line count
    gives exactly the frames × points the reader reads, so the limit holds at its boundary."""
    path = corpus_dir / take
    read = read_take(path)
    size = read.n_frames * read.n_keypoints
    kind = "trc" if path.suffix == ".trc" else "mediapipe-csv"
    check_frame_points(path, kind, ReadLimits(max_frame_points=size))
    with pytest.raises(TooLargeError, match=rf"^{path.name}: .*max_frame_points"):
        check_frame_points(path, kind, ReadLimits(max_frame_points=size - 1))


def test_keypoint_csv_lines_skip_its_comment_header(tmp_path: Path) -> None:
    path = tmp_path / "old.csv"
    rows = [f"{f},{k},0,0,0" for f in range(10) for k in "abc"]
    path.write_text("# fps: 30\n# unit: m\n\nframe,keypoint,x,y,z\n" + "\n".join(rows))
    assert read_take(path).n_frames * 3 == 30
    check_frame_points(path, "csv", ReadLimits(max_frame_points=30))
    with pytest.raises(TooLargeError, match="got 30 data lines"):
        check_frame_points(path, "csv", ReadLimits(max_frame_points=29))


def test_sparse_frame_numbers_are_refused_by_the_readers_before_the_arrays() -> None:
    """Three lines whose frame numbers (and names) span 9 frames: within the line count,
    refused by the long-CSV readers themselves, before they make the arrays."""
    data = b"frame,keypoint,x,y\n0,a,0,0\n4,b,0,0\n8,c,0,0\n"
    assert parse_keypoint_csv(data, "s.csv", 30, limits=ReadLimits(max_frame_points=27))
    with pytest.raises(TooLargeError, match=r"^s.csv: .*got 9 × 3"):
        parse_keypoint_csv(data, "s.csv", 30, limits=ReadLimits(max_frame_points=26))
    landmarks = b"frame_number,landmark,x,y,z\n0,0,0,0,0\n4,0,0,0,0\n8,0,0,0,0\n"
    assert parse_mediapipe_csv(landmarks, "m.csv", limits=ReadLimits(max_frame_points=9 * 33))
    with pytest.raises(TooLargeError, match=r"^m.csv: .*got 9 × 33"):
        parse_mediapipe_csv(landmarks, "m.csv", limits=ReadLimits(max_frame_points=9 * 33 - 1))


def _npy_with_header(text_from: str, text_to: str) -> bytes:
    """A valid (10, 21, 4) ``.npy`` whose header's ``text_from`` became ``text_to`` (same
    header length, padded with spaces: the data that follows is the real 6,720 bytes)."""
    buffer = io.BytesIO()
    np.save(buffer, np.zeros((10, 21, 4)))
    data = buffer.getvalue()
    size = int.from_bytes(data[8:10], "little")
    header = data[10 : 10 + size].decode("latin1").replace(text_from, text_to).rstrip()
    assert len(header) < size
    return data[:10] + (header.ljust(size - 1) + "\n").encode("latin1") + data[10 + size :]


@pytest.mark.parametrize("limits", [None, ReadLimits()])
def test_npy_header_claiming_a_huge_shape_is_refused_before_allocating(
    tmp_path: Path, limits: ReadLimits | None
) -> None:
    # 100,000,000 × 21 × 4 float64 is 62.6 GiB: NumPy allocated it before reading the data.
    path = tmp_path / "kp_shapelie.npy"
    path.write_bytes(_npy_with_header("(10, 21, 4)", "(100000000, 21, 4)"))
    error = ParseError if limits is None else TooLargeError
    with pytest.raises(error, match=r"kp_shapelie\.npy") as caught:
        read_take(path, fps=30.0, limits=limits)
    assert ("holds, got a header declaring 67200000000" in str(caught.value)) is (limits is None)


@pytest.mark.parametrize(
    ("header", "message"),
    [
        # The tokenizer's error (NumPy retries a header as Python 2's) escaped as a traceback.
        ("'shape': (10, 21, 4), }", '\'shape\': (10, 21, 4 """'),
        ("(10, 21, 4)", "(-10, 21, 4)"),
        ("(10, 21, 4)", "(1, 1, 100000000000000000000000000000)"),
        ("'<f8'", "'|O'"),
    ],
)
def test_malformed_npy_headers_are_parse_errors_naming_the_file(
    tmp_path: Path, header: str, message: str
) -> None:
    path = tmp_path / "bad.npy"
    path.write_bytes(_npy_with_header(header, message))
    for limits in (None, ReadLimits()):
        with pytest.raises((ParseError, TooLargeError), match=r"bad\.npy: Expected") as caught:
            read_take(path, fps=30.0, limits=limits)
        assert "allow_pickle" not in str(caught.value)
        assert "Traceback" not in str(caught.value)


def test_numpy_files_of_objects_or_pickles_get_our_message_not_numpys(tmp_path: Path) -> None:
    objects = tmp_path / "objects.npy"
    np.save(objects, np.array([[[1, 2, 3]]], dtype=object), allow_pickle=True)
    archive = tmp_path / "objects.npz"
    np.savez(archive, positions=np.array([[[1, 2, 3]]], dtype=object))
    pickled = tmp_path / "pickled.npy"
    pickled.write_bytes(pickle.dumps([1, 2, 3]))
    for path in (objects, archive, pickled):
        with pytest.raises(ParseError, match=re.escape(path.name)) as caught:
            read_take(path, fps=30.0)
        assert "allow_pickle" not in str(caught.value)
        assert "unsafe" not in str(caught.value)
    with pytest.raises(ParseError, match="array of Python objects"):
        read_take(objects, fps=30.0)


def test_npz_member_headers_are_checked_before_loading(tmp_path: Path) -> None:
    # A stored member whose header claims 2,000,000 × 33 × 4 (2.1 GB) over 6,720 bytes.
    lying = _npy_with_header("(10, 21, 4)", "(2000000, 33, 4)")
    path = tmp_path / "lie.npz"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("positions.npy", lying)
    with pytest.raises(ParseError, match=r"field 'positions'.* declaring 2112000000"):
        read_take(path, fps=30.0)
    with pytest.raises(TooLargeError, match=r"max_frame_points.* 2000000 × 33"):
        read_take(path, fps=30.0, limits=ReadLimits())
    raw = tmp_path / "raw.npz"
    with zipfile.ZipFile(raw, "w") as archive:
        archive.writestr("positions", b"not an array")  # AttributeError in the reader
    with pytest.raises(ParseError, match="field 'positions': Expected a NumPy array"):
        read_take(raw, fps=30.0)
