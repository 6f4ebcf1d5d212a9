"""Runs of frames: hysteresis, gap closing, short runs, per-run reductions."""

from __future__ import annotations

import numpy as np
import pytest

from mocapqa.errors import ShapeError
from mocapqa.feet.runs import (
    close_short_gaps,
    column_runs,
    drop_short_runs,
    hysteresis,
    paint_runs,
    run_maximum,
    run_mean,
)


def col(values: str) -> np.ndarray:
    return np.array([c == "1" for c in values])[:, None]


def test_hysteresis_enters_on_the_strict_condition_and_leaves_when_the_loose_one_fails() -> None:
    enter = col("0011000000")
    stay = col("0111110111")
    assert "".join("1" if v else "0" for v in hysteresis(enter, stay)[:, 0]) == "0011110000"


def test_hysteresis_ignores_an_entry_where_the_keep_condition_fails() -> None:
    assert not hysteresis(col("0100"), col("0011")).any()


def test_runs_are_listed_by_column_then_start_with_inclusive_ends() -> None:
    mask = np.stack([col("0110011")[:, 0], col("1000000")[:, 0]], axis=1)
    columns, starts, ends = column_runs(mask)
    assert columns.tolist() == [0, 0, 1]
    assert starts.tolist() == [1, 5, 0]
    assert ends.tolist() == [2, 6, 0]
    assert np.array_equal(paint_runs((columns, starts, ends), mask.shape), mask)


def test_short_interior_gaps_close_and_gaps_at_the_ends_stay() -> None:
    closed = close_short_gaps(col("0110110001"), 2)[:, 0]
    assert "".join("1" if v else "0" for v in closed) == "0111110001"


def test_short_runs_are_dropped() -> None:
    kept = drop_short_runs(col("1101110"), 3)[:, 0]
    assert "".join("1" if v else "0" for v in kept) == "0001110"


def test_run_reductions_stay_inside_their_runs() -> None:
    values = np.array([[1.0, 5.0], [2.0, np.nan], [9.0, 7.0], [4.0, 3.0]])
    runs = (np.array([0, 1]), np.array([0, 1]), np.array([1, 3]))
    assert run_maximum(values, runs)[0] == 2.0
    assert run_mean(values, runs).tolist() == [1.5, 5.0]


def test_a_mask_must_be_two_dimensional() -> None:
    with pytest.raises(ShapeError, match=r"Expected `mask` to have shape \(F, N\)"):
        column_runs(np.zeros(5, dtype=bool))
