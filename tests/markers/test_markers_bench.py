"""The swap bench's pieces on one small real take (the full bench is ``mocapqa bench
markers``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mocapqa.markers.params import MarkerParams
from mocapqa_bench.markers import (
    Counts,
    clean_flags,
    load_takes,
    swap_trials,
    tiled_take,
)


def test_trials_count_found_and_false_swaps(corpus_dir: Path) -> None:
    [take] = load_takes(corpus_dir, ["btk/Eb015pr.c3d"])
    [(counts, confident)] = swap_trials(take, range(3), [MarkerParams()])
    assert counts.injected == confident.injected == 6
    assert counts.found >= 5
    assert counts.false <= 1
    assert confident.found <= counts.found
    assert clean_flags(take, MarkerParams())[0] == 0.0


def test_counts_give_precision_recall_and_f1() -> None:
    counts = Counts(10, 8, 2) + Counts(10, 10, 0)
    assert (counts.recall, counts.precision) == (0.9, 0.9)
    assert abs(counts.f1 - 0.9) < 1e-12
    assert Counts().recall is None
    assert Counts().f1 == 0.0


def test_a_tiled_take_has_the_asked_size_and_no_jump(corpus_dir: Path) -> None:
    takes = load_takes(corpus_dir, ["cmu/cmu_02_05.c3d", "vicon/nick_freeform_001.c3d"])
    positions, names = tiled_take(takes, frames=5000, markers=60)
    assert positions.shape == (5000, 60, 3)
    assert len(set(names)) == 60
    steps = np.linalg.norm(np.diff(positions[:, :41], axis=0), axis=2)
    original = np.linalg.norm(np.diff(takes[0].positions, axis=0), axis=2)
    assert np.nanmax(steps) <= np.nanmax(original) + 1e-9
