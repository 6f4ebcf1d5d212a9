"""Seeded corruption of CSV, TRC and JSON inputs: only InputError subclasses may come out."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError
from mocapqa.io.keypoint_csv import parse_keypoint_csv
from mocapqa.io.keypoint_json import parse_keypoint_json
from mocapqa.io.mediapipe import parse_mediapipe_csv, parse_mediapipe_json
from mocapqa.io.openpose import parse_openpose_frame
from mocapqa.io.trc import format_trc, parse_trc, read_trc

STATIC_TRC = "keypoints/pose2sim/S00_P00_T00_StaticTrial/pose-3d/S00_P00_T00_StaticTrial_0-12.trc"
OPENPOSE_FRAME = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose/cam01_json/cam01.0000.json"
TOKENS = [b"nan", b"inf", b"-inf", b"1e999", b"NaN", b",", b"\t", b"\n", b"\r\n", b'"',
          b"{", b"]", b"null", b"-", b"1e-400", b"\x00", b"\xff\xfe", b"\xe9", b"#", b"0",
          b"-1"]  # fmt: skip


def _mutate(data: bytes, rng: np.random.Generator) -> bytes:
    size = len(data)
    kind = int(rng.integers(7))
    a, b = sorted(int(v) for v in rng.integers(0, size + 1, 2))
    if kind == 0:
        return data[:a]
    if kind == 1:
        return data[:a] + data[b:]
    if kind == 2:
        return data[:a] + TOKENS[int(rng.integers(len(TOKENS)))] + data[a:]
    if kind == 3:
        return (
            data[:a]
            + bytes(rng.integers(0, 256, int(rng.integers(1, 9)), dtype=np.uint8))
            + data[a:]
        )
    if kind == 4:
        lines = data.split(b"\n")
        i, j = (int(v) for v in rng.integers(0, len(lines), 2))
        lines[i], lines[j] = lines[j], lines[i]
        return b"\n".join(lines)
    if kind == 5:
        seps = [b",", b"\t", b" "]
        sep = seps[int(rng.integers(3))]
        cells = data.split(sep)
        i, j = (int(v) for v in rng.integers(0, len(cells), 2))
        cells[i], cells[j] = cells[j], cells[i]
        if rng.random() < 0.5 and len(cells) > 1:
            del cells[int(rng.integers(len(cells)))]
        return sep.join(cells)
    return data[:a] + TOKENS[int(rng.integers(len(TOKENS)))] + data[b:]


def _fuzz(parse: Callable[[bytes], object], seed_text: bytes, seed: int, count: int) -> int:
    rng = np.random.default_rng(seed)
    failures = 0
    for _ in range(count):
        data = seed_text
        for _ in range(int(rng.integers(1, 4))):
            data = _mutate(data, rng)
        try:
            result = parse(data)
        except InputError:
            failures += 1
            continue
        if isinstance(result, KeypointSequence):
            assert not np.any(np.isinf(result.positions))
    return failures


def _keypoint_csv() -> bytes:
    rows = ["# fps: 30", "# unit: m", "frame,time,keypoint,x,y,z,confidence"]
    for frame in range(4):
        for name in ("nose", "neck", "hip"):
            rows.append(f"{frame},{frame / 30!r},{name},0.{frame}1,1.2,-0.5,0.9")
    return ("\n".join(rows) + "\n").encode()


def _mediapipe_csv(corpus_dir: Path) -> bytes:
    path = corpus_dir / "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv"
    return b"\n".join(path.read_bytes().split(b"\n")[:70]) + b"\n"


def _trc(corpus_dir: Path) -> bytes:
    seq = read_trc(corpus_dir / STATIC_TRC)
    small = KeypointSequence(
        seq.names[:3], seq.positions[:3, :3], seq.confidence[:3, :3], 60.0, "m"
    )
    # Pose2Sim layout: no blank line before the data
    return format_trc(small).replace("\n\n", "\n").encode()


def test_corrupted_inputs_raise_only_input_errors(corpus_dir: Path) -> None:
    trc = _trc(corpus_dir)
    json_doc = (
        b'{"fps": 30, "unit": "m", "keypoints": ["a", "b"],\n"frames": [[[1.5, 2, 3, 0.5], null],'
        b"\n[[1, 2, 3, 1], [4, 5, 6]]]}\n"
    )
    openpose = (corpus_dir / OPENPOSE_FRAME).read_bytes()
    mediapipe_json = (
        "[[" + ",".join(['{"x": 0.1, "y": 0.2, "z": 0.3, "visibility": 0.9}'] * 33) + "]]"
    ).encode()
    cases: list[tuple[Callable[[bytes], object], bytes, int]] = [
        (lambda d: parse_keypoint_csv(d, "fuzz.csv"), _keypoint_csv(), 1500),
        (lambda d: parse_mediapipe_csv(d, "fuzz.csv", fps=30), _mediapipe_csv(corpus_dir), 400),
        (lambda d: parse_trc(d, "fuzz.trc"), trc, 1200),
        (lambda d: parse_keypoint_json(d, "fuzz.json"), json_doc, 1000),
        (lambda d: parse_openpose_frame(d, "fuzz.json"), openpose, 300),
        (lambda d: parse_mediapipe_json(d, "fuzz.json"), mediapipe_json, 300),
    ]
    for seed, (parse, text, count) in enumerate(cases):
        parse(text)  # the uncorrupted seed input parses
        failures = _fuzz(parse, text, seed, count)
        assert failures > count // 10, f"case {seed}: corruption was almost never detected"


@pytest.mark.parametrize("text", [b"", b"\x00\x01\x02", b"\xff" * 20, b"frame\n", b"nan,inf\n"])
def test_degenerate_csv_inputs(text: bytes) -> None:
    with pytest.raises(InputError, match="Expected"):
        parse_keypoint_csv(text, "x.csv", fps=30)
