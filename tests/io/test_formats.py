"""Format detection, dispatch and the write-by-extension entry point."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ParseError, UnsupportedFormatError
from mocapqa.io.formats import KEYPOINT_FORMATS, detect_format, read_take, write_keypoints
from mocapqa.io.keypoint_layouts import MEDIAPIPE_33_NAMES as MP

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


def _huge_value_takes(folder: Path, corpus_dir: Path) -> dict[str, Path]:
    """A take of every keypoint format with one coordinate of 1e308 (the rest ordinary)."""
    positions = np.arange(2 * 2 * 3, dtype=float).reshape(2, 2, 3) / 10
    positions[1, 1, 0] = 0.123456  # written as text, then replaced by 1e308
    seq = KeypointSequence(("a", "b"), positions, np.ones((2, 2)), 30.0, length_unit="m")
    paths: dict[str, Path] = {}
    for kind in ("csv", "json", "trc"):
        path = folder / f"take.{kind}"
        write_keypoints(path, seq)
        text = path.read_text(encoding="utf-8")
        assert text.count("0.123456") == 1, kind
        path.write_text(text.replace("0.123456", "1e308"), encoding="utf-8")
        paths[kind] = path
    huge = positions.copy()
    huge[1, 1, 0] = 1e308
    np.save(folder / "take.npy", huge)
    np.savez(folder / "take.npz", positions=huge, fps=np.float64(30))
    paths["npy"], paths["npz"] = folder / "take.npy", folder / "take.npz"
    openpose = folder / "openpose"
    openpose.mkdir()
    frame = json.loads((DATA / "openpose_body25_frame.json").read_text(encoding="utf-8"))
    frame["people"][0]["pose_keypoints_2d"][0] = 1e308
    (openpose / "cam.0000.json").write_text(json.dumps(frame), encoding="utf-8")
    paths["openpose"] = openpose
    landmarks = [{"x": 1e308 if i == 3 else 0.1, "y": i, "z": 0.5} for i in range(33)]
    (folder / "mp.json").write_text(json.dumps([landmarks]), encoding="utf-8")
    paths["mediapipe-json"] = folder / "mp.json"
    rows = "".join(f"0,{name},{'1e308' if i == 3 else 0.1},0.2,0.3\n" for i, name in enumerate(MP))
    (folder / "mp.csv").write_text("frame_number,landmark,x,y,z\n" + rows, encoding="utf-8")
    paths["mediapipe-csv"] = folder / "mp.csv"
    pbtxt = (corpus_dir / MEDIAPIPE / "google_mediapipe_testdata/pose_landmarks.pbtxt").read_text()
    (folder / "mp.pbtxt").write_text(pbtxt.replace("x: 0.46507242", "x: 1e308", 1))
    paths["mediapipe-pbtxt"] = folder / "mp.pbtxt"
    return paths


def test_every_keypoint_reader_refuses_coordinates_beyond_1e9(
    tmp_path: Path, corpus_dir: Path
) -> None:
    # The BVH reader and the filters refused 1e308; the keypoint readers read it, and convert
    # wrote it out.
    paths = _huge_value_takes(tmp_path, corpus_dir)
    assert set(paths) == set(KEYPOINT_FORMATS)
    for kind, path in paths.items():
        assert detect_format(path) == kind
        with pytest.raises(ParseError, match=r"within ±1,000,000,000, got 1e\+308") as caught:
            read_take(path, fps=30.0)
        assert caught.value.field == "positions", kind
        assert caught.value.path == str(path) or path.name in str(caught.value), kind


@pytest.mark.parametrize("kind", ["json", "mediapipe-json", "openpose"])
def test_json_readers_name_the_nesting_they_parse(tmp_path: Path, kind: str) -> None:
    from mocapqa.io.keypoint_input import JSON_PARSE_DEPTH
    from mocapqa.io.keypoint_json import parse_keypoint_json
    from mocapqa.io.mediapipe import parse_mediapipe_json
    from mocapqa.io.openpose import parse_openpose_frame

    deep = "[" * 5000 + "]" * 5000  # RecursionError in json.loads without the check
    parse = {
        "json": lambda: parse_keypoint_json(deep, "deep.json", fps=30.0),
        "mediapipe-json": lambda: parse_mediapipe_json(deep, "deep.json", fps=30.0),
        "openpose": lambda: parse_openpose_frame(deep, "deep.json"),
    }[kind]
    with pytest.raises(ParseError, match=f"nested at most {JSON_PARSE_DEPTH} deep"):
        parse()
