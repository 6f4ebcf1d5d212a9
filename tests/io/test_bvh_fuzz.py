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


def outcome(data: bytes, name: str, reader: NumberReader) -> Motion | str:
    """The parsed take, or the InputError's message; anything else fails the test."""
    try:
        return parse_bvh(data, name, number_reader=reader)
    except InputError as e:
        return str(e)
    except Exception as e:  # the test's point: report what escaped, and on what
        pytest.fail(f"{name}: {type(e).__name__}: {e}\n{data[:3000]!r}")


def test_corrupted_takes_raise_only_input_errors(small_take: bytes) -> None:
    """Both number readers give the same take or the same error on every corruption."""
    rng = np.random.default_rng(20240611)
    outcomes = {"read": 0, "refused": 0}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for case in range(N_CASES):
            data = corrupt(small_take, rng)
            result = outcome(data, f"case{case}.bvh", "arrow")
            careful = outcome(data, f"case{case}.bvh", "python")
            if isinstance(result, str):
                assert result == careful, f"case {case}"
                outcomes["refused"] += 1
                continue
            assert isinstance(careful, Motion), f"case {case}: {careful}"
            np.testing.assert_array_equal(result.quats, careful.quats)
            np.testing.assert_array_equal(result.translations, careful.translations)
            outcomes["read"] += 1
    # The corruptions must exercise both outcomes in earnest.
    assert outcomes["refused"] > N_CASES // 4
    assert outcomes["read"] > N_CASES // 50


def frame_layouts(take: bytes) -> dict[str, bytes]:
    """The take with its frame lines laid out in the ways exporters and editors write them."""
    head, rest = take.split(b"Frame Time:", 1)
    time_line, block = rest.split(b"\n", 1)
    rows = [line.split() for line in block.splitlines() if line.strip()]

    def joined(sep: bytes, end: bytes, lead: bytes = b"") -> bytes:
        return b"".join(lead + sep.join(row) + end for row in rows)

    layouts = {
        "single spaces": joined(b" ", b"\n"),
        "trailing space": joined(b" ", b" \n"),
        "CRLF": joined(b" ", b"\r\n"),
        "trailing space CRLF": joined(b" ", b" \r\n"),
        "double spaces": joined(b"  ", b"\n"),
        "leading space": joined(b" ", b"\n", b" "),
        "tabs": joined(b"\t", b"\n"),
        "blank lines": joined(b" ", b"\n\n"),
        "whitespace-only lines": joined(b" ", b"\n \n"),
        "no final newline": joined(b" ", b"\n")[:-1],
        # Wrong: a lone CR is whitespace, so two frames share one line.
        "lone CR": joined(b" ", b"\r"),
        # Wrong: one value too many where the trailing space would be.
        "extra value": joined(b" ", b" \n").replace(b" \n", b" 1\n", 1),
        "extra value, last line": joined(b" ", b" \n")[:-2] + b" 1\n",
        "mixed trailing spaces": joined(b" ", b" \n").replace(b" \n", b"\n", 1),
        # Wrong: the first frame is one value short.
        "missing value": joined(b" ", b" \n").replace(b" " + rows[0][-1] + b" \n", b" \n", 1),
    }
    return {
        name: head + b"Frame Time:" + time_line + b"\n" + block for name, block in layouts.items()
    }


@pytest.mark.parametrize("layout", sorted(frame_layouts(b"Frame Time: 1\n1\n")))
def test_number_readers_agree_on_frame_layouts(small_take: bytes, layout: str) -> None:
    data = frame_layouts(small_take)[layout]
    result = outcome(data, f"{layout}.bvh", "arrow")
    careful = outcome(data, f"{layout}.bvh", "python")
    if isinstance(careful, str):
        assert result == careful
        assert layout in {"lone CR", "extra value", "extra value, last line", "missing value"}
    else:
        assert isinstance(result, Motion), result
        np.testing.assert_array_equal(result.quats, careful.quats)
        np.testing.assert_array_equal(result.translations, careful.translations)
        assert result.n_frames == 4
