"""Swaps repaired before gaps are filled, by one accept rule, on a real take."""

from __future__ import annotations

import numpy as np
import pytest
from tests.markers.conftest import Take

from mocapqa.errors import InputError
from mocapqa.markers.inject import inject_swaps
from mocapqa.markers.params import MarkerParams
from mocapqa.markers.repair import repair_markers
from mocapqa.markers.segments import pair_stats


def test_a_swap_is_repaired_before_the_gap_beside_it_is_filled(
    clean_takes: dict[str, Take],
) -> None:
    take = clean_takes["cmu/cmu_02_05.c3d"]
    clean = take.positions[:600]
    stats = pair_stats(clean, take.length_unit, MarkerParams())
    swapped, (truth,) = inject_swaps(clean, np.random.default_rng(3), stats, take.fps)
    # A gap in one of the swapped markers just after the swap's release: filled from the
    # samples either side, it would draw the other marker's path into the gap unless the
    # swap is repaired first.
    gap = slice(truth.end + 3, truth.end + 9)
    hidden = swapped.copy()
    hidden[gap, truth.a] = np.nan
    residuals = np.where(np.isnan(hidden).any(axis=-1), -1.0, 0.5)

    repaired = repair_markers(hidden, residuals, take.names, take.fps, take.length_unit)
    (swap,) = repaired.repaired
    assert set(swap.indices) == {truth.a, truth.b}
    assert abs(swap.start - truth.start) <= 2
    assert abs(swap.end - truth.end) <= 2
    outside = np.ones(clean.shape[:2], dtype=bool)
    outside[gap, truth.a] = False
    outside[swap.start : swap.end + 1, [truth.a, truth.b]] = False
    outside &= ~repaired.filled
    assert np.array_equal(repaired.positions[outside], hidden[outside], equal_nan=True)
    assert repaired.filled[gap, truth.a].all()
    assert np.all(repaired.residuals[gap, truth.a] == 0)
    error = np.linalg.norm(repaired.positions[gap, truth.a] - clean[gap, truth.a], axis=-1)
    assert error.max() < 20.0  # mm
    account = repaired.to_json(take.names, take.length_unit)
    assert account["filled_samples"] == repaired.filled.sum()
    assert account["swaps"][0]["applied"]

    untouched = repair_markers(hidden, residuals, take.names, take.fps, take.length_unit, "none")
    assert np.array_equal(untouched.positions, hidden, equal_nan=True)
    assert np.array_equal(untouched.residuals, residuals)
    assert [s["applied"] for s in untouched.to_json(take.names, "mm")["swaps"]] == [False]


def test_a_chosen_set_of_swaps_replaces_the_rule_for_swaps_only(
    clean_takes: dict[str, Take],
) -> None:
    take = clean_takes["cmu/cmu_02_05.c3d"]
    clean = take.positions[:600]
    stats = pair_stats(clean, take.length_unit, MarkerParams())
    swapped, _ = inject_swaps(clean, np.random.default_rng(3), stats, take.fps)
    residuals = np.where(np.isnan(swapped).any(axis=-1), -1.0, 0.5)
    args = (swapped, residuals, take.names, take.fps, take.length_unit)

    ruled = repair_markers(*args)
    assert ruled.repaired
    chosen = repair_markers(*args, swaps={0})
    assert chosen.swaps == ruled.swaps  # found again, in the same order
    assert chosen.repaired == (ruled.swaps[0],)
    assert np.array_equal(chosen.positions, ruled.positions, equal_nan=True)
    none = repair_markers(*args, swaps=())
    assert none.repaired == ()
    kept = ~none.filled  # the fills still follow the rule
    assert np.array_equal(none.positions[kept], swapped[kept], equal_nan=True)
    with pytest.raises(InputError, match="swap ids"):
        repair_markers(*args, swaps={len(ruled.swaps)})
