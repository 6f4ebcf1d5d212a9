"""Format detection, dispatch and the write-by-extension entry point."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ParseError, UnsupportedFormatError
from mocapqa.io.formats import KEYPOINT_FORMATS, detect_format, read_take, write_keypoints

TRIAL = "keypoints/pose2sim/S00_P00_T01_BalancingTrial"
MEDIAPIPE = "keypoints/mediapipe"
DATA = Path(__file__).resolve().parents[1] / "data"


def test_corpus_files_are_detected(corpus_dir: Path, cmu_walk: Path) -> None:
    assert detect_format(cmu_walk) == "bvh"
    assert (
        detect_format(corpus_dir / TRIAL / "pose-3d/S00_P00_T01_BalancingTrial_0-100.trc") == "trc"
    )
    assert detect_format(corpus_dir / TRIAL / "pose/cam01_json") == "openpose"
    assert detect_format(corpus_dir / TRIAL / "pose/cam01_json/cam01.0000.json") == "openpose"
    csv_path = corpus_dir / MEDIAPIPE / "etfrobotics_full-body-kinematics/landmarks.csv"
    assert detect_format(csv_path) == "mediapipe-csv"
    pbtxt = corpus_dir / MEDIAPIPE / "google_mediapipe_testdata/pose_landmarks.pbtxt"
    assert detect_format(pbtxt) == "mediapipe-pbtxt"
    assert set(KEYPOINT_FORMATS) >= {
        "trc",
        "openpose",
        "mediapipe-csv",
        "csv",
        "npy",
        "npz",
        "json",
    }


def test_every_keypoint_file_of_the_corpus_reads(corpus_dir: Path) -> None:
    takes = sorted(corpus_dir.glob("keypoints/**/*.trc"))
    takes += sorted(corpus_dir.glob(f"{TRIAL}/pose*/cam*_json"))
    takes += sorted(corpus_dir.glob("keypoints/mediapipe/*/*.*"))
    assert len(takes) == 6 + 4 + 2
    for path in takes:
        seq = read_take(path)
        assert isinstance(seq, KeypointSequence), path
        assert seq.n_frames > 0
        assert seq.source_format == detect_format(path)


def test_bvh_goes_through_the_bvh_reader(cmu_walk: Path) -> None:
    motion = read_take(cmu_walk)
    assert isinstance(motion, Motion)


def test_content_sniffing_without_extension(
    corpus_dir: Path, tmp_path: Path, cmu_walk: Path
) -> None:
    pairs = {
        "walk": cmu_walk,
        "markers": corpus_dir / TRIAL / "pose-3d/S00_P00_T01_BalancingTrial_0-100.trc",
        "frame": DATA / "openpose_body25_frame.json",
        "landmarks": corpus_dir / MEDIAPIPE / "etfrobotics_full-body-kinematics/landmarks.csv",
    }
    for name, source in pairs.items():
        shutil.copy(source, tmp_path / f"{name}.dat")
    assert detect_format(tmp_path / "walk.dat") == "bvh"
    assert detect_format(tmp_path / "markers.dat") == "trc"
    assert detect_format(tmp_path / "frame.dat") == "openpose"
    assert detect_format(tmp_path / "landmarks.dat") == "mediapipe-csv"
    np.save(tmp_path / "arr.npy", np.zeros((2, 3, 4)))
    shutil.move(tmp_path / "arr.npy", tmp_path / "arr.bin")
    assert detect_format(tmp_path / "arr.bin") == "npy"


def test_generic_json_and_csv_are_told_apart(tmp_path: Path) -> None:
    (tmp_path / "a.json").write_text('{"fps": 30, "keypoints": ["a"], "frames": [[[1, 2, 3]]]}')
    (tmp_path / "b.json").write_text("[[" + ",".join(['{"x": 1, "y": 2, "z": 3}'] * 33) + "]]")
    (tmp_path / "c.csv").write_text("frame,time,keypoint,x,y,z\n0,0,a,1,2,3\n")
    assert detect_format(tmp_path / "a.json") == "json"
    assert detect_format(tmp_path / "b.json") == "mediapipe-json"
    assert detect_format(tmp_path / "c.csv") == "csv"


def test_unknown_formats_raise_unsupported(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("hello there\n")
    with pytest.raises(UnsupportedFormatError, match="Expected one of bvh, trc"):
        detect_format(tmp_path / "notes.txt")
    seq = KeypointSequence(("a",), np.zeros((1, 1, 3)), np.ones((1, 1)), 30.0)
    with pytest.raises(UnsupportedFormatError, match="Expected a keypoint output format"):
        write_keypoints(tmp_path / "out.xlsx", seq)
    with pytest.raises(ParseError, match="Expected an existing file"):
        detect_format(tmp_path / "absent.trc")


def test_write_format_overrides_the_extension(tmp_path: Path) -> None:
    seq = KeypointSequence(("a",), np.ones((2, 1, 3)), np.ones((2, 1)), 30.0, "m")
    write_keypoints(tmp_path / "out.txt", seq, format="json")
    again = read_take(tmp_path / "out.txt")
    assert isinstance(again, KeypointSequence)
    assert again.length_unit == "m"
