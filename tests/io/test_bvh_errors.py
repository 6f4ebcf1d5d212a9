"""Malformed BVH raises ParseError naming the line and what was expected."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tests.io.bvh_variants import chain

from mocapqa.errors import InputError, ParseError
from mocapqa.io.bvh import parse_bvh, read_bvh
from mocapqa.io.bvh_hierarchy import MAX_JOINTS
from mocapqa.io.bvh_write import channel_values

# Line numbers are 1-based; the comments give them.
GOOD_LINES = [
    "HIERARCHY",  # 1
    "ROOT Hips",  # 2
    "{",  # 3
    "  OFFSET 0 0 0",  # 4
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation",  # 5
    "  JOINT Spine",  # 6
    "  {",  # 7
    "    OFFSET 0 10 0",  # 8
    "    CHANNELS 3 Zrotation Yrotation Xrotation",  # 9
    "    End Site",  # 10
    "    {",  # 11
    "      OFFSET 0 5 0",  # 12
    "    }",  # 13
    "  }",  # 14
    "}",  # 15
    "MOTION",  # 16
    "Frames: 2",  # 17
    "Frame Time: 0.0333333",  # 18
    "0 90 0 0 0 0 10 20 30",  # 19
    "1 91 0 1 2 3 11 21 31",  # 20
]


def bvh(lines: list[str], newline: str = "\n") -> str:
    return newline.join(lines) + newline


def replaced(number: int, text: str | None) -> list[str]:
    """GOOD_LINES with line ``number`` (1-based) replaced, or removed when ``text`` is None."""
    lines = list(GOOD_LINES)
    if text is None:
        del lines[number - 1]
    else:
        lines[number - 1] = text
    return lines


def test_the_good_file_reads_with_any_line_endings() -> None:
    for newline in ("\n", "\r\n", "\r"):
        motion = parse_bvh(bvh(GOOD_LINES, newline))
        assert motion.n_frames == 2
        assert motion.skeleton.names == ("Hips", "Spine")
        np.testing.assert_array_equal(channel_values(motion)[1], [1, 91, 0, 1, 2, 3, 11, 21, 31])


@pytest.mark.parametrize(
    ("lines", "pattern"),
    [
        (GOOD_LINES[:19], r"line 20: Expected 2 frame lines \(Frames:\), got 1 \(truncated"),
        (GOOD_LINES[:12], r"line 12: Expected '}', got end of file \(truncated file\?\)"),
        (GOOD_LINES[:15], r"line 15: Expected a 'MOTION' section, got end of file"),
        (replaced(19, "0 90 0 0 0 0 10 20"), r"line 19: Expected 9 values on a frame line, got 8"),
        (replaced(20, "1 91 0 1 2 3 11 abc 31"), r"line 20: Expected a number, got 'abc'"),
        (replaced(20, "1 91 0 1 2 3 11 1,5 31"), r"line 20: Expected a number, got '1,5'"),
        (replaced(19, "0 90 0 0 nan 0 10 20 30"), r"line 19: Expected finite numbers, got NaN"),
        (
            replaced(20, "1 91 0 1 2 3 11 21 inf"),
            r"line 20: Expected finite numbers, got NaN or inf",
        ),
        (replaced(20, "1 91 0 1 2 3 11 21 1e999"), r"line 20: Expected finite numbers"),
        (replaced(16, None), r"line 16: Expected 'ROOT' or 'MOTION', got 'Frames:'"),
        (replaced(17, None), r"line 17: Expected 'Frames:', got 'Frame Time: 0.0333333'"),
        (replaced(17, "Frames: two"), r"line 17: Expected a frame count, got 'two'"),
        (replaced(17, "Frames: -1"), r"line 17: Expected a frame count >= 0, got -1"),
        (replaced(18, None), r"line 18: Expected 'Frame Time:', got '0 90 0 0 0 0 10 20 30'"),
        (replaced(18, "Frame Time: 0"), r"line 18: Expected a frame time > 0 s, got '0'"),
        (replaced(18, "Frame Time: -0.01"), r"line 18: Expected a frame time > 0 s, got '-0.01'"),
        (replaced(18, "Frame Time: nan"), r"line 18: Expected a frame time > 0 s, got 'nan'"),
        (replaced(14, None), r"line 14: Expected 'OFFSET', 'CHANNELS', 'JOINT', 'End' or '}', got"),
        (replaced(15, "} }"), r"line 15: Expected 'ROOT' or 'MOTION', got '}'"),
        (replaced(6, "  JOINT Hips"), r"line 6: Expected unique joint names, got 'Hips' twice"),
        (replaced(8, "    OFFSET 0 ten 0"), r"line 8: Expected a number for OFFSET y, got 'ten'"),
        (replaced(9, "    CHANNELS 3 Zrotation Yrotation Wrotation"), r"line 9: Expected a chan"),
        (replaced(9, "    CHANNELS 2 Zrotation Yrotation"), r"line 9: Expected 0 or 3 distinct"),
        (replaced(9, "    CHANNELS 7 Zrotation"), r"line 9: Expected 0 to 6 channels, got 7"),
        (replaced(1, "HIERARCHIE"), r"line 1: Expected 'HIERARCHY', got 'HIERARCHIE'"),
        (replaced(2, "JOINT Hips"), r"line 2: Expected 'ROOT', got 'JOINT'"),
    ],
)
def test_malformed_text_names_the_line(lines: list[str], pattern: str) -> None:
    with pytest.raises(ParseError, match=pattern):
        parse_bvh(bvh(lines), "take.bvh")


def test_unbalanced_braces_report_end_of_hierarchy() -> None:
    lines = replaced(15, "")  # the root's closing brace is missing
    with pytest.raises(ParseError, match=r"line 14: Expected .*got end of hierarchy \(truncated"):
        parse_bvh(bvh(lines))


def test_error_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.bvh"
    path.write_text(bvh(replaced(19, "0 90 0")), encoding="utf-8")
    with pytest.raises(ParseError, match=r"broken\.bvh, line 19: Expected 9 values") as info:
        read_bvh(path)
    assert info.value.line == 19
    assert info.value.path == str(path)


def test_more_than_max_joints_is_refused() -> None:
    data = chain(MAX_JOINTS + 1)
    # The 1001st joint's name is on line 2 + 4 * 1000 = 4002.
    with pytest.raises(ParseError, match=r"line 4002: Expected at most 1000 joints, got more"):
        parse_bvh(data)


def test_binary_file_is_refused() -> None:
    data = b"HIERARCHY\n\x00\x01\x02\xff" * 10
    with pytest.raises(ParseError, match=r"line 1: Expected a text file, got binary data"):
        parse_bvh(data, "image.png")


def test_undecodable_bytes_name_their_line() -> None:
    data = bvh(GOOD_LINES).encode().replace(b"Spine", b"Sp\xffine")
    with pytest.raises(ParseError, match=r"line 6: Expected UTF-8 or ASCII text"):
        parse_bvh(data)


def test_missing_file_is_an_input_error(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"Expected a readable file"):
        read_bvh(tmp_path / "absent.bvh")


def test_a_huge_frame_count_is_a_truncation_not_an_allocation() -> None:
    lines = replaced(17, "Frames: 99999999999999")
    with pytest.raises(ParseError, match=r"line 21: Expected 99999999999999 frame lines"):
        parse_bvh(bvh(lines))


def test_extra_frame_lines_are_refused() -> None:
    lines = [*GOOD_LINES, "2 92 0 1 2 3 11 21 31"]
    with pytest.raises(ParseError, match=r"line 21: Expected 2 frame lines \(Frames:\), got more"):
        parse_bvh(bvh(lines))
