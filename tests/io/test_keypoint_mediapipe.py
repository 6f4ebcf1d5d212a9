"""MediaPipe readers: the ETF Robotics world-landmark CSV, the Google pbtxt, and JSON exports."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from mocapqa.errors import ParseError
from mocapqa.io.keypoint_layouts import MEDIAPIPE_33_NAMES
from mocapqa.io.mediapipe import (
    parse_mediapipe_csv,
    parse_mediapipe_json,
    read_mediapipe_csv,
    read_mediapipe_pbtxt,
)

CSV = "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv"
PBTXT = "keypoints/mediapipe/google_mediapipe_testdata/pose_landmarks.pbtxt"


def test_world_landmark_csv_matches_the_readme(corpus_dir: Path) -> None:
    seq = read_mediapipe_csv(corpus_dir / CSV, fps=90)
    assert (seq.n_frames, seq.n_keypoints) == (340, 33)
    assert seq.names == MEDIAPIPE_33_NAMES
    assert seq.fps == 90.0
    assert seq.length_unit == "m"
    assert seq.missing_fraction == 0.0
    assert np.all(seq.confidence == 1.0)
    steps = np.linalg.norm(np.diff(seq.positions, axis=0), axis=-1)
    assert 0.003 < float(np.median(steps)) < 0.012
    assert 0.15 < float(steps.max()) < 0.3
    with (corpus_dir / CSV).open() as handle:
        rows = list(csv.DictReader(handle))
    last = rows[-1]
    assert seq.positions[int(last["frame_number"]), 32, 1] == float(last["y"])


def test_csv_without_fps_records_the_assumed_rate(corpus_dir: Path) -> None:
    seq = read_mediapipe_csv(corpus_dir / CSV)
    assert seq.fps == 30.0
    assert any("fps 30 assumed" in note for note in seq.assumptions)


def test_pbtxt_golden_frame(corpus_dir: Path) -> None:
    seq = read_mediapipe_pbtxt(corpus_dir / PBTXT)
    assert (seq.n_frames, seq.n_keypoints) == (1, 33)
    assert seq.length_unit == "normalized"
    np.testing.assert_array_equal(seq.positions[0, 0], [0.46507242, 0.41610304, -0.14999297])
    assert seq.confidence[0, 0] == 0.99998844
    np.testing.assert_array_equal(seq.positions[0, 32], [0.30121577, 0.94473803, -0.08448716])
    assert seq.confidence[0, 32] == 0.97545445


def _landmarks(value: float) -> list[dict[str, float]]:
    return [{"x": value, "y": i, "z": 0.5, "visibility": 0.25} for i in range(33)]


def test_json_list_and_frames_forms() -> None:
    listed = parse_mediapipe_json(json.dumps([_landmarks(0.1), _landmarks(0.2)]), fps=25)
    framed = parse_mediapipe_json(
        json.dumps(
            {"fps": 25, "frames": [{"landmarks": _landmarks(0.1)}, {"landmarks": _landmarks(0.2)}]}
        )
    )
    for seq in (listed, framed):
        assert (seq.n_frames, seq.fps, seq.length_unit) == (2, 25.0, "unknown")
        assert seq.positions[1, 4].tolist() == [0.2, 4.0, 0.5]
        assert np.all(seq.confidence == 0.25)


def test_json_frame_without_detection_is_missing() -> None:
    seq = parse_mediapipe_json(json.dumps([_landmarks(0.1), []]), fps=30)
    assert seq.missing[1].all()
    assert not seq.missing[0].any()


def test_json_wrong_landmark_count_names_the_field() -> None:
    with pytest.raises(ParseError, match=r"field 'frames\[0\]': Expected 33 landmarks, got 2"):
        parse_mediapipe_json(json.dumps([_landmarks(0.1)[:2]]), "m.json")


def test_csv_unknown_landmark_names_line() -> None:
    text = "frame_number,landmark,x,y,z\n0,NOSE,1,2,3\n0,TAIL,1,2,3\n"
    with pytest.raises(ParseError, match=r"line 3, field 'landmark'"):
        parse_mediapipe_csv(text, "m.csv")


def test_pbtxt_refuses_deep_nesting_and_names_the_line() -> None:
    from mocapqa.errors import ParseError
    from mocapqa.io.mediapipe import parse_mediapipe_pbtxt

    # 100,000 nested blocks (1.4 MB) used to take over a minute; refused at the ninth level.
    deep = "landmarks {\n" * 100_000 + "}\n" * 100_000
    with pytest.raises(ParseError, match="nested at most 8 deep") as caught:
        parse_mediapipe_pbtxt(deep, "deep.pbtxt")
    assert caught.value.line == 9


def test_pbtxt_names_the_line_of_a_bad_token_after_many_landmarks() -> None:
    from mocapqa.errors import ParseError
    from mocapqa.io.mediapipe import parse_mediapipe_pbtxt

    text = "landmarks {\n" + " landmark { x: 1 y: 1 z: 1 }\n" * 5000 + " landmark { x: ! }\n}\n"
    with pytest.raises(ParseError) as caught:
        parse_mediapipe_pbtxt(text, "many.pbtxt")
    assert caught.value.line == 5002
