"""Errors of the long keypoint CSV reader name the line and the column, confidence included."""

from __future__ import annotations

import pytest

from mocapqa.errors import ParseError
from mocapqa.io.keypoint_csv import parse_keypoint_csv

HEADER = "frame,keypoint,x,y,z,confidence"


def _take(last_row: str) -> str:
    """Two good rows, then ``last_row`` on line 4."""
    return "\n".join([HEADER, "0,nose,0.1,0.2,0.3,0.9", "1,nose,0.1,0.2,0.3,1", last_row]) + "\n"


@pytest.mark.parametrize("confidence", ["2", "-1", "nan", "1.0001"])
def test_a_confidence_outside_0_to_1_names_its_line_and_column(confidence: str) -> None:
    with pytest.raises(ParseError) as caught:
        parse_keypoint_csv(_take(f"2,nose,0.1,0.2,0.3,{confidence}"), "take.csv", fps=30.0)
    assert caught.value.line == 4
    assert caught.value.field == "confidence"
    assert caught.value.message.startswith("Expected confidence in [0, 1], got ")
    assert "line 4, field 'confidence'" in str(caught.value)


@pytest.mark.parametrize(
    ("row", "column"),
    [
        ("2,nose,abc,0.2,0.3,0.5", "x"),
        ("2,nose,0.1,0.2,0.3,abc", "confidence"),
        ("2,,0.1,0.2,0.3,0.5", "keypoint"),
        ("2.5,nose,0.1,0.2,0.3,0.5", "frame"),
    ],
)
def test_every_cell_error_names_its_column(row: str, column: str) -> None:
    with pytest.raises(ParseError) as caught:
        parse_keypoint_csv(_take(row), "take.csv", fps=30.0)
    assert (caught.value.line, caught.value.field) == (4, column)


@pytest.mark.parametrize("confidence", ["0", "1", "0.5", ""])
def test_confidences_from_0_to_1_and_empty_cells_are_read(confidence: str) -> None:
    seq = parse_keypoint_csv(_take(f"2,nose,0.1,0.2,0.3,{confidence}"), "take.csv", fps=30.0)
    expected = 1.0 if confidence == "" else float(confidence)
    assert seq.confidence[2, 0] == pytest.approx(expected)
