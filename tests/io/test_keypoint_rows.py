"""Rows of a long keypoint table placed in dense arrays (:mod:`mocapqa.io.keypoint_rows`)."""

from __future__ import annotations

import numpy as np
import pytest

from mocapqa.errors import ParseError, TooLargeError
from mocapqa.io.guards import ReadLimits
from mocapqa.io.keypoint_rows import MAX_FRAME_GAP_FACTOR, KeypointRow, dense_keypoints


def _repeat(frame: int, point: int) -> str:
    return f"Expected one row per frame and point, got point {point} twice in frame {frame}"


def test_rows_fill_the_span_from_the_first_to_the_last_frame_number() -> None:
    rows: list[KeypointRow] = [
        (10, 1, [1.0, 2.0, 3.0], 0.5, 2),
        (12, 0, [4.0, 5.0, 6.0], 1.0, 3),
    ]
    dense = dense_keypoints(rows, 2, "take.csv", None, _repeat)
    assert dense.first == 10
    assert dense.n_frames == 3
    np.testing.assert_array_equal(dense.positions[0, 1], [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(dense.positions[2, 0], [4.0, 5.0, 6.0])
    assert np.isnan(dense.positions[1]).all()
    np.testing.assert_array_equal(dense.confidence, [[0.0, 0.5], [0.0, 0.0], [1.0, 0.0]])


def test_a_repeated_frame_and_point_names_the_second_row_s_line() -> None:
    rows: list[KeypointRow] = [
        (0, 0, [0.0, 0.0, 0.0], 1.0, 2),
        (0, 0, [1.0, 1.0, 1.0], 1.0, 7),
    ]
    with pytest.raises(ParseError, match=r"line 7.*point 0 twice in frame 0"):
        dense_keypoints(rows, 1, "take.csv", None, _repeat)


def test_a_stray_frame_number_far_beyond_the_rows_is_refused() -> None:
    far = MAX_FRAME_GAP_FACTOR * 2
    rows: list[KeypointRow] = [
        (0, 0, [0.0, 0.0, 0.0], 1.0, 2),
        (far, 0, [0.0, 0.0, 0.0], 1.0, 3),
    ]
    with pytest.raises(ParseError, match=f"contiguous frame numbers, got a span of {far + 1}"):
        dense_keypoints(rows, 1, "take.csv", None, _repeat)


def test_the_reading_limits_refuse_the_arrays_before_they_are_made() -> None:
    rows: list[KeypointRow] = [(f, 0, [0.0, 0.0, 0.0], 1.0, f + 2) for f in range(20)]
    with pytest.raises(TooLargeError, match="max_frame_points"):
        dense_keypoints(rows, 1, "take.csv", ReadLimits(max_frame_points=10), _repeat)
