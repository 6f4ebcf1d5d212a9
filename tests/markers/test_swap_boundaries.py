"""The swap check's boundary test (two labels well apart cannot exchange without a jump) and
the leave-one-file-out choice of the swap thresholds."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from tests.markers.conftest import Take

from mocapqa.markers.params import MarkerParams
from mocapqa.markers.segments import pair_stats
from mocapqa.markers.swap_evidence import labels_held
from mocapqa.markers.swaps import find_swaps
from mocapqa_bench.markers import Counts, GridRow, best_point

NICK = "vicon/nick_freeform_001.c3d"


def _pair(frames: int = 40, apart: float = 50.0) -> np.ndarray:
    """Two markers ``apart`` mm apart moving together along x at 2 mm per frame, ``(F, 2, 3)``."""
    t = np.arange(frames, dtype=np.float64)
    positions = np.zeros((frames, 2, 3))
    positions[:, :, 0] = 2.0 * t[:, None]
    positions[:, 1, 1] = apart
    return positions


def test_labels_that_move_on_smoothly_are_held_and_an_exchange_is_not() -> None:
    params = MarkerParams()
    positions = _pair()
    assert labels_held(positions, 0, 1, 50.0, 20, params)
    swapped = positions.copy()
    swapped[20:30] = swapped[20:30, ::-1]
    assert not labels_held(swapped, 0, 1, 50.0, 20, params)
    assert not labels_held(swapped, 0, 1, 50.0, 30, params)
    # The jump one frame off the boundary is still inside the window.
    assert not labels_held(swapped, 0, 1, 50.0, 22, params)
    assert labels_held(swapped, 0, 1, 50.0, 25, params)


def test_labels_are_held_at_any_speed_from_their_predicted_positions() -> None:
    # Two markers 80 mm apart along their motion, moving 100–180 mm per frame: each label's
    # step is as long as the step to the other's previous position, so only a prediction
    # from their velocities tells that they keep their trajectories.
    t = np.arange(40, dtype=np.float64)
    positions = np.zeros((40, 2, 3))
    positions[:, :, 0] = (100.0 * t + 2.0 * t**2)[:, None]
    positions[:, 1, 0] -= 80.0
    positions[:, 1, 1] = 5.0
    kept = np.linalg.norm(positions[20] - positions[19], axis=1).sum()
    exchanged = np.linalg.norm(positions[20] - positions[19, ::-1], axis=1).sum()
    assert exchanged - kept < 1.0
    params = MarkerParams()
    assert labels_held(positions, 0, 1, 80.0, 20, params)
    swapped = positions.copy()
    swapped[20:30] = swapped[20:30, ::-1]
    assert not any(labels_held(swapped, 0, 1, 80.0, f, params) for f in (18, 20, 22, 30))


def test_a_boundary_that_cannot_be_told_does_not_reject() -> None:
    params = MarkerParams()
    positions = _pair()
    # A marker missing at the window's end: the exchange may have happened out of sight.
    missing = positions.copy()
    missing[22, 1] = np.nan
    assert not labels_held(missing, 0, 1, 50.0, 20, params)
    # Missing inside the window: bridged, the labels still move on smoothly.
    inside = positions.copy()
    inside[20, 1] = np.nan
    assert labels_held(inside, 0, 1, 50.0, 20, params)
    # Two markers passing within a few millimetres of each other may exchange unseen.
    close = _pair(apart=5.0)
    assert not labels_held(close, 0, 1, 50.0, 20, params)
    # Too near the take's edges for the window.
    assert not labels_held(positions, 0, 1, 50.0, 3, params)
    assert not labels_held(positions, 0, 1, 50.0, 38, params)
    assert not labels_held(positions, 0, 1, float("nan"), 20, params)


@pytest.mark.parametrize("misfit", [2.0, 2.5])
def test_the_vicon_take_has_no_false_swap_at_low_misfit_thresholds(
    clean_takes: dict[str, Take], misfit: float
) -> None:
    # Without the boundary test the wrist markers LIWR/LOHAND, each measured against one
    # other mate, were a swap over frames 171–180 (misfit 2.5) or 171–189 (misfit 2): their
    # distance to LOWR departs by ~7 mm while both labels move on without a jump.
    take = clean_takes[NICK]
    params = dataclasses.replace(MarkerParams(), swap_misfit=misfit)
    stats = pair_stats(take.positions, take.length_unit, params)
    assert find_swaps(take.positions, take.names, stats, take.length_unit, params) == []
    # The test is what removes it: a boundary never held reports the interval again.
    loose = dataclasses.replace(params, swap_held=1e6)
    found = find_swaps(take.positions, take.names, stats, take.length_unit, loose)
    assert {frozenset(s.markers) for s in found} == {frozenset({"Nick01:LIWR", "Nick01:LOHAND"})}


def test_an_injected_swap_survives_the_boundary_test(clean_takes: dict[str, Take]) -> None:
    take = clean_takes[NICK]
    names = list(take.names)
    a, b = names.index("Nick01:RKNE"), names.index("Nick01:RHEL")
    swapped = take.positions.copy()
    swapped[300:360, [a, b]] = swapped[300:360, [b, a]]
    params = dataclasses.replace(MarkerParams(), swap_misfit=2.0)
    stats = pair_stats(swapped, take.length_unit, params)
    found = find_swaps(swapped, take.names, stats, take.length_unit, params)
    assert [(set(s.indices), s.start, s.end) for s in found] == [({a, b}, 300, 359)]


def _row(found: int, false: int, clean: bool) -> GridRow:
    counts = Counts(10, found, false)
    return GridRow(counts, counts, clean)


def test_the_choice_skips_points_with_clean_swaps_and_leaves_the_file_out() -> None:
    # Three takes × three grid points.
    table = [
        [_row(10, 0, True), _row(10, 0, False), _row(9, 0, True)],
        [_row(8, 0, True), _row(10, 0, True), _row(9, 0, True)],
        [_row(5, 5, True), _row(10, 0, True), _row(10, 0, True)],
    ]
    # Point 1 is best on takes 1 and 2 but has a false swap on take 0's clean take.
    assert best_point(table, [0, 1, 2])[0] == 2
    index, pooled = best_point(table, [1, 2])
    assert index == 1
    assert pooled == Counts(20, 20, 0)
    # Ties go to the first point.
    assert best_point(table, [0])[0] == 0
