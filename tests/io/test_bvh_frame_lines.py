"""The fast frame formatter writes exactly the text of Python's "%.6f" on rounded values."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import channel_values, frame_lines


def _reference(values: np.ndarray, precision: int) -> list[str]:
    rows = (np.round(values, precision) + 0.0).tolist()
    return [" ".join(f"%.{precision}f" % v for v in row) for row in rows]


@pytest.mark.parametrize("precision", [0, 3, 6])
def test_random_values_of_every_magnitude(precision: int) -> None:
    for seed in range(60):
        rng = np.random.default_rng(seed)
        shape = (int(rng.integers(1, 25)), int(rng.integers(1, 40)))
        values = rng.normal(0, 10.0 ** float(rng.integers(-9, 9)), shape)
        values[rng.random(shape) < 0.1] = 0.0
        values[rng.random(shape) < 0.05] = -0.0
        values.flat[0] = -0.5 * 10.0**-precision  # rounds to -0: written "0..."
        assert frame_lines(values, precision) == _reference(values, precision), seed


def test_values_past_the_fast_range_and_non_finite() -> None:
    values = np.array([[1e15, -3.25, np.nan], [np.inf, 0.0, -1e-7]])
    assert frame_lines(values) == _reference(values, 6)


def test_real_take_channels(corpus_dir: Path) -> None:
    motion = read_bvh(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    values = channel_values(motion)
    assert values.shape[0] == motion.n_frames
    assert frame_lines(values) == _reference(values, 6)
