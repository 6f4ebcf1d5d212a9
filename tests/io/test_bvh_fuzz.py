"""Seeded corruptions of a real BVH: the reader either reads them or raises an InputError.

Nothing else may escape (IndexError, RecursionError, ValueError, numpy warnings as errors...).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.io.bvh import NumberReader, parse_bvh

N_CASES = 3000
TOKENS = [
    b"{", b"}", b"ROOT", b"JOINT", b"End", b"Site", b"OFFSET", b"CHANNELS", b"MOTION",
    b"Frames:", b"Frame Time:", b"HIERARCHY", b"Xposition", b"Zrotation", b"0", b"-0", b"7",
    b"-1", b"1e400", b"nan", b"-inf", b"1.2.3", b"--4", b"+5", b".", b"e", b"1e", b"99999999",
    b"\t", b"\r\n", b"\n", b" ", b"\x00", b"\xff\xfe", b"\xc3\xa9", b"\xe2\x80\xa8", b"'",
]  # fmt: skip


@pytest.fixture(scope="module")
def small_take(corpus_dir: Path) -> bytes:
    """A real file (pybvh's bvh_test2.bvh) cut to its first 4 frames, so each parse is quick."""
    text = (corpus_dir / "bvh" / "misc" / "bvh_test2.bvh").read_bytes()
    head, motion = text.split(b"MOTION", 1)
    lines = [line for line in motion.splitlines() if line.strip()]
    frames = lines[2:6]
    assert len(frames) == 4
    assert lines[0].startswith(b"Frames:")
    return head + b"MOTION\nFrames: 4\n" + lines[1] + b"\n" + b"\n".join(frames) + b"\n"


def corrupt(data: bytes, rng: np.random.Generator) -> bytes:
    """One to three random edits: truncation, deletion, insertion, token swap or noise."""
    out = bytearray(data)
    for _ in range(int(rng.integers(1, 4))):
        kind = int(rng.integers(0, 7))
        at = int(rng.integers(0, len(out) + 1))
        if kind == 0:
            del out[at:]
        elif kind == 1:
            del out[at : at + int(rng.integers(1, 40))]
        elif kind == 2:
            out[at:at] = TOKENS[int(rng.integers(0, len(TOKENS)))]
        elif kind == 3:
            words = bytes(out).split(b" ")
            if len(words) > 2:
                i, j = rng.integers(0, len(words), size=2)
                words[i], words[j] = words[j], words[i]
                out = bytearray(b" ".join(words))
        elif kind == 4:
            n = int(rng.integers(1, 16))
            out[at : at + n] = rng.integers(0, 256, size=n, dtype=np.uint8).tobytes()
        elif kind == 5:
            lines = bytes(out).split(b"\n")
            i = int(rng.integers(0, len(lines)))
            lines.insert(i, lines[int(rng.integers(0, len(lines)))])
            out = bytearray(b"\n".join(lines))
        else:
            words = bytes(out).split()
            if words:
                words[int(rng.integers(0, len(words)))] = TOKENS[int(rng.integers(0, len(TOKENS)))]
                out = bytearray(b" ".join(words) if rng.random() < 0.2 else b"\n".join(words))
    return bytes(out)


def test_the_uncorrupted_take_reads(small_take: bytes) -> None:
    motion = parse_bvh(small_take)
    assert motion.n_frames == 4


def test_corrupted_takes_raise_only_input_errors(small_take: bytes) -> None:
    rng = np.random.default_rng(20240611)
    readers: tuple[NumberReader, ...] = ("python", "arrow")
    outcomes = {"read": 0, "refused": 0}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for case in range(N_CASES):
            data = corrupt(small_take, rng)
            try:
                result = parse_bvh(data, f"case{case}.bvh", number_reader=readers[case % 2])
            except InputError:
                outcomes["refused"] += 1
                continue
            except Exception as e:  # the test's point: report what escaped, and on what
                pytest.fail(f"case {case}: {type(e).__name__}: {e}\n{data[:3000]!r}")
            assert isinstance(result, Motion)
            outcomes["read"] += 1
    # The corruptions must exercise both outcomes in earnest.
    assert outcomes["refused"] > N_CASES // 4
    assert outcomes["read"] > N_CASES // 50
