"""The feet bench on one real take: injected slides and penetrations are found, the clean take
is not flagged, and the bench's split keeps 005_05 out of parameter choice."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.feet.params import FeetParams
from mocapqa.io.bvh import read_bvh
from mocapqa.pipeline.feet import motion_foot_points
from mocapqa_bench.feet import BenchTake, clean_flags, run_trials


@pytest.fixture(scope="module")
def bandai_walk(corpus_dir: Path) -> BenchTake:
    path = corpus_dir / "bvh" / "bandai" / "dataset-1_walk_normal_001.bvh"
    points, _ = motion_foot_points(read_bvh(path, length_unit="cm"))
    return BenchTake(path.name, "bandai", False, points, 1.0, True)


def test_the_clean_bandai_walk_has_no_skate(bandai_walk: BenchTake) -> None:
    sizes, contacts = clean_flags(bandai_walk, FeetParams())
    assert sizes == []
    assert contacts == 13


def test_slides_of_5_cm_and_sinks_of_3_cm_are_found_with_their_size(
    bandai_walk: BenchTake,
) -> None:
    trials = run_trials(bandai_walk, FeetParams(), seed=0, slides_cm=(5.0,), depths_cm=(3.0,))
    slides = [t for t in trials if t.kind == "slide"]
    sinks = [t for t in trials if t.kind == "penetration"]
    assert len(slides) == 13
    assert len(sinks) >= 10
    # At 30 fps a slide against the walking direction partly cancels the foot's own landing
    # and push-off, so a few read short; the last contact (5 frames) is too short to hold one.
    assert sum(t.found for t in slides) >= 11
    assert np.median([t.measured_cm for t in slides]) == pytest.approx(4.8, abs=0.4)
    assert all(t.found for t in sinks)
    assert all(abs(t.measured_cm - 3.0) < 0.3 for t in sinks)


def test_slides_of_half_a_cm_are_mostly_not_reported(bandai_walk: BenchTake) -> None:
    # The threshold is 0.014 leg (1.1 cm on this 80-cm leg): 1-cm slides sit on it.
    trials = run_trials(bandai_walk, FeetParams(), seed=0, slides_cm=(0.5,), depths_cm=())
    assert sum(t.found for t in trials) <= 2
