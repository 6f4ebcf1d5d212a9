"""OpenPose JSON reader on the Pose2Sim camera folders and a hand-made BODY_25 frame."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mocapqa.errors import ParseError
from mocapqa.io.keypoint_layouts import BODY_25_NAMES, BODY_25B_NAMES
from mocapqa.io.openpose import openpose_frame_files, parse_openpose_frame, read_openpose

TRIAL = "keypoints/pose2sim/S00_P00_T01_BalancingTrial"
DATA = Path(__file__).resolve().parents[1] / "data"


def test_associated_folders_have_the_readme_zero_counts(corpus_dir: Path) -> None:
    for cam, zeroed in (("cam01", 90), ("cam02", 6)):
        seq = read_openpose(corpus_dir / TRIAL / "pose-associated" / f"{cam}_json")
        assert seq.n_frames == 100
        assert seq.n_keypoints == 25
        assert seq.names == BODY_25B_NAMES
        assert int(seq.missing.sum()) == zeroed
        assert seq.length_unit == "px"
        assert seq.n_dims == 2
        assert np.all(seq.positions[~seq.missing][:, 2] == 0.0)
        assert np.all(np.isnan(seq.positions[seq.missing]))
        assert np.all(seq.confidence[seq.missing] == 0.0)
        assert seq.fps == 30.0
        assert any("fps 30 assumed" in note for note in seq.assumptions)


def test_raw_cam01_zeroed_keypoints_over_all_people(corpus_dir: Path) -> None:
    folder = corpus_dir / TRIAL / "pose" / "cam01_json"
    people = [read_openpose(folder, person_index=i) for i in range(3)]
    # person 2 appears in one frame only; its 99 absent frames count 25 missing each
    total = sum(int(p.missing.sum()) for p in people) - 99 * 25
    assert total == 399


def test_raw_cam02_low_confidence_count(corpus_dir: Path) -> None:
    folder = corpus_dir / TRIAL / "pose" / "cam02_json"
    people = [read_openpose(folder, person_index=i) for i in range(2)]
    low = sum(int(((p.confidence > 0) & (p.confidence < 0.3)).sum()) for p in people)
    assert low == 1036
    with pytest.raises(ParseError, match="Expected person 2 in at least one frame"):
        read_openpose(folder, person_index=2)


def test_frames_are_in_file_number_order(corpus_dir: Path) -> None:
    folder = corpus_dir / TRIAL / "pose-associated" / "cam02_json"
    files = openpose_frame_files(folder)
    assert [f.name for f in files[:3]] == ["cam02.0000.json", "cam02.0001.json", "cam02.0002.json"]
    seq = read_openpose(folder, fps=60)
    frame = parse_openpose_frame(files[57].read_bytes(), files[57])
    assert frame is not None
    found = frame[:, 2] > 0
    np.testing.assert_array_equal(seq.positions[57, found, :2], frame[found, :2])
    np.testing.assert_array_equal(seq.confidence[57, found], frame[found, 2])
    assert seq.fps == 60.0
    assert seq.assumptions == ("layout BODY_25B assumed for 25 OpenPose keypoints",)


def test_single_file_and_body25_layout_are_recognised() -> None:
    seq = read_openpose(DATA / "openpose_body25_frame.json")
    assert seq.n_frames == 1
    assert seq.names == BODY_25_NAMES
    assert seq.missing[0].tolist() == [name == "LEar" for name in BODY_25_NAMES]
    forced = read_openpose(DATA / "openpose_body25_frame.json", layout="BODY_25B")
    assert forced.names == BODY_25B_NAMES


def test_coco18_names_for_18_keypoints(tmp_path: Path) -> None:
    flat = [float(v) for i in range(18) for v in (10 * i, 5 * i, 0.5)]
    (tmp_path / "f_0.json").write_text(json.dumps({"people": [{"pose_keypoints_2d": flat}]}))
    seq = read_openpose(tmp_path)
    assert seq.names[:3] == ("Nose", "Neck", "RShoulder")
    assert seq.n_keypoints == 18


def test_broken_json_names_file_and_line(tmp_path: Path) -> None:
    (tmp_path / "f_0.json").write_text('{"people": [\n{"pose_keypoints_2d": [1, 2,]}]}')
    with pytest.raises(ParseError, match=r"f_0\.json, line 2: Expected valid JSON"):
        read_openpose(tmp_path)


def test_bad_triples_name_the_field(tmp_path: Path) -> None:
    (tmp_path / "f_0.json").write_text('{"people": [{"pose_keypoints_2d": [1, 2]}]}')
    with pytest.raises(ParseError, match=r"field 'people\[0\]\.pose_keypoints_2d'"):
        read_openpose(tmp_path)


def test_empty_folder_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match="Expected OpenPose"):
        read_openpose(tmp_path)
