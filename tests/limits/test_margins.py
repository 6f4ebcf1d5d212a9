"""The per-joint margin experiment's two building blocks: widening a margin-0 map equals
building with the margin, and the nested choice takes the smallest margin meeting the target."""

from __future__ import annotations

import numpy as np
import pytest

from mocapqa.limits.occupancy import OccupancyParams, build_occupancy, evaluate
from mocapqa_bench.limits_margins import MARGINS_DEG, MarginCounts, choose_margins, widened


@pytest.mark.parametrize("margin", [0.0, 40.0, 90.0])
def test_widening_a_margin_free_map_equals_building_with_the_margin(margin: float) -> None:
    rng = np.random.default_rng(3)
    # twists spread across ±180° in some bins, so the π cap and the wrap both occur; twists
    # beyond π (read as their wrapped angle) once gave arcs wider than 2π: sorted before wrapping
    params = np.column_stack(
        [rng.normal(0, 0.6, 4000), rng.normal(0, 0.6, 4000), rng.uniform(-np.pi, np.pi, 4000)]
    )
    params[:2000, 2] = rng.normal(2.9, 0.4, 2000)
    settings = OccupancyParams(bin_deg=15.0, dilation_bins=2, interpolate=True)
    built = build_occupancy(params, OccupancyParams(15.0, 2, margin, True, True))
    again = widened(build_occupancy(params, settings), margin)
    probe = np.column_stack(
        [rng.uniform(-2, 2, 20000), rng.uniform(-2, 2, 20000), rng.uniform(-np.pi, np.pi, 20000)]
    )
    assert np.array_equal(evaluate(built, probe)[0], evaluate(again, probe)[0])
    np.testing.assert_allclose(evaluate(built, probe)[2], evaluate(again, probe)[2], atol=1e-9)


def test_the_smallest_margin_meeting_the_target_on_average_is_chosen() -> None:
    m = len(MARGINS_DEG)
    frames = np.array([1000, 1000])
    # role 0: 5 % at margin 0, 2 % at 10°, 0.5 % from 20° on (on average over both rigs);
    # role 1: never under 1 %, fewest flags at the largest margin
    first = np.zeros((m, 2), dtype=np.int64)
    first[:, 0] = [50, 20, 5] + [5] * (m - 3)
    first[:, 1] = np.linspace(300, 30, m).astype(np.int64)
    second = first.copy()
    second[1, 0] = 0  # on average 1 % at 10°: still not ≤ 1 % … it is: (2 % + 0 %) / 2
    inner = [
        MarginCounts(("a", "b"), first, frames, []),
        MarginCounts(("a", "b"), second, frames, []),
    ]
    chosen = choose_margins(inner, 0.01)
    assert [MARGINS_DEG[c] for c in chosen] == [10.0, MARGINS_DEG[-1]]
    # on the worst inner rig role 0 is at 2 % at 10°, so the worst-rig rule takes 20°
    assert [MARGINS_DEG[c] for c in choose_margins(inner, 0.01, "worst")] == [20.0, MARGINS_DEG[-1]]
    with pytest.raises(ValueError, match="same roles"):
        choose_margins([inner[0], MarginCounts(("b", "a"), first, frames, [])], 0.01)
