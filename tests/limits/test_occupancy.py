"""The lookup map: occupancy, twist bounds, smoothing, widening, validity and distances.

Expected values here are worked out by hand from the map's definition (methods §2).
"""

from __future__ import annotations

import numpy as np
import pytest

from mocapqa.errors import InputError, ShapeError
from mocapqa.limits.occupancy import (
    MIN_BIN_DEG,
    OccupancyParams,
    build_occupancy,
    evaluate,
    is_valid,
    limit_distances,
    signed_excess,
    swing_bins,
    twist_bounds,
)

D = np.deg2rad


def _samples(rows: list[tuple[float, float, float]]) -> np.ndarray:
    return np.asarray(D(np.array(rows, dtype=float)), dtype=np.float64)


def test_a_bin_keeps_the_twist_range_of_its_samples() -> None:
    samples = _samples([(0.5, 0.5, -10.0), (0.2, 0.7, 25.0)])
    occupancy = build_occupancy(samples, OccupancyParams(bin_deg=1.0, smooth=False))
    i1, i2 = swing_bins(samples[:1], 1.0)
    assert (int(i1[0]), int(i2[0])) == (180, 180)
    assert occupancy.occupied.sum() == 1
    np.testing.assert_allclose(np.rad2deg(occupancy.tau_min[180, 180]), -10.0)
    np.testing.assert_allclose(np.rad2deg(occupancy.tau_max[180, 180]), 25.0)


def test_validity_needs_an_occupied_bin_and_a_twist_inside_its_bounds() -> None:
    occupancy = build_occupancy(
        _samples([(0.5, 0.5, -10.0), (0.5, 0.5, 20.0)]), OccupancyParams(bin_deg=1.0)
    )
    queries = _samples([(0.9, 0.1, 0.0), (0.9, 0.1, 30.0), (1.5, 0.5, 0.0)])
    np.testing.assert_array_equal(is_valid(occupancy, queries), [True, False, False])


def test_smoothing_averages_bounds_over_occupied_neighbours_only() -> None:
    # Two side-by-side bins with twist maxima 0° and 16°: the 3×3 kernel weighs the centre 4
    # and the side neighbour 2, so the smoothed maxima are (4·0 + 2·16)/6 and (2·0 + 4·16)/6.
    samples = _samples([(0.5, 0.5, 0.0), (1.5, 0.5, 16.0)])
    occupancy = build_occupancy(samples, OccupancyParams(bin_deg=1.0))
    np.testing.assert_allclose(np.rad2deg(occupancy.tau_max[180, 180]), 32.0 / 6.0)
    np.testing.assert_allclose(np.rad2deg(occupancy.tau_max[181, 180]), 64.0 / 6.0)


def test_dilation_and_margin_widen_the_map() -> None:
    samples = _samples([(2.5, 2.5, 0.0), (2.5, 2.5, 10.0)])
    occupancy = build_occupancy(
        samples, OccupancyParams(bin_deg=5.0, dilation_bins=1, tau_margin_deg=5.0)
    )
    assert occupancy.occupied.sum() == 9
    np.testing.assert_allclose(np.rad2deg(occupancy.tau_min[occupancy.occupied]), -5.0)
    np.testing.assert_allclose(np.rad2deg(occupancy.tau_max[occupancy.occupied]), 15.0)


def test_distances_are_zero_inside_and_measure_swing_and_twist_outside() -> None:
    occupancy = build_occupancy(
        _samples([(0.5, 0.5, 0.0), (0.5, 0.5, 10.0)]), OccupancyParams(bin_deg=1.0)
    )
    queries = _samples([(0.5, 0.5, 5.0), (0.5, 0.5, 30.0), (4.0, 0.5, 5.0), (4.0, 5.0, -5.0)])
    swing, twist = limit_distances(occupancy, queries)
    # Bin [0°, 1°]²: (4, 0.5) is 3° right of it; (4, 5) is 3° right and 4° above, 5° away.
    np.testing.assert_allclose(swing, [0.0, 0.0, 3.0, 5.0], atol=1e-9)
    np.testing.assert_allclose(twist, [0.0, 20.0, 0.0, 5.0], atol=1e-9)


def test_bad_settings_and_samples_are_refused() -> None:
    with pytest.raises(InputError, match="Expected `bin_deg` dividing 360"):
        OccupancyParams(bin_deg=7.0)
    with pytest.raises(ShapeError, match=r"Expected `params` to have shape \(N, 3\)"):
        build_occupancy(np.zeros((4, 2)), OccupancyParams())


def test_twist_bounds_wrap_at_180_degrees() -> None:
    # One swing bin whose twists straddle ±180°: the shortest covering arc, not its complement.
    tau = np.deg2rad([170.0, 175.0, 179.0, -178.0, -172.0])
    params = np.column_stack((np.zeros(5), np.zeros(5), tau))
    occupancy = build_occupancy(params, OccupancyParams(bin_deg=15.0, tau_margin_deg=5.0))
    probe = np.array([[0.0, 0.0, np.deg2rad(d)] for d in (179.9, -179.9, 168.0, -168.0, 0.0)])
    np.testing.assert_array_equal(is_valid(occupancy, probe), [True, True, True, True, False])
    # Outside by 10° the short way round (160° → arc from 165°), not 325° the long way.
    _, twist = limit_distances(occupancy, np.array([[0.0, 0.0, np.deg2rad(155.0)]]))
    np.testing.assert_allclose(twist, [10.0], atol=1e-6)


def test_interpolated_bounds_are_continuous_across_bin_edges() -> None:
    # Two neighbouring bins with twist ranges ±10° and ±50°.
    rows = [(np.deg2rad(s1), 0.0, np.deg2rad(t)) for s1, t in
            ((-7.0, -10.0), (-7.0, 10.0), (7.0, -50.0), (7.0, 50.0))]  # fmt: skip
    params = np.array(rows)
    for interpolate, jump in ((False, 40.0), (True, 0.0)):
        settings = OccupancyParams(bin_deg=15.0, smooth=False, interpolate=interpolate)
        occupancy = build_occupancy(params, settings)
        edge = 0.0  # between the bins [−15°, 0°) and [0°, 15°)
        probe = np.array([[edge - 1e-6, 0.0, 0.0], [edge + 1e-6, 0.0, 0.0]])
        _, half = twist_bounds(occupancy, probe)
        assert abs(np.rad2deg(half[1] - half[0]) - jump) < 1e-3
    # Between the two bin centres (−7.5°, 7.5°) the half-width goes linearly from 10° to 50°.
    probe = np.array([[np.deg2rad(s1), 0.0, 0.0] for s1 in (-7.5, -3.75, 3.75, 7.5)])
    np.testing.assert_allclose(np.rad2deg(twist_bounds(occupancy, probe)[1]), [10, 20, 40, 50])


def _brute_force_arc(tau: np.ndarray) -> tuple[float, float]:
    """Centre and half-width of the shortest arc covering ``tau``, on a 0.01° grid of starts."""
    best = (0.0, np.pi)
    for start in np.deg2rad(np.arange(-180.0, 180.0, 0.01)):
        width = float(np.max((tau - start) % (2 * np.pi)))
        if width < 2 * best[1]:
            best = (start + width / 2, width / 2)
    return float((best[0] + np.pi) % (2 * np.pi) - np.pi), best[1]


def test_every_bin_keeps_the_shortest_arc_of_its_twists() -> None:
    rng = np.random.default_rng(4)
    for centre_deg in (0.0, 170.0, -175.0):
        tau = np.deg2rad(centre_deg + rng.uniform(-30.0, 30.0, 12))
        tau = (tau + np.pi) % (2 * np.pi) - np.pi
        occupancy = build_occupancy(
            np.c_[np.full((12, 2), D(0.5)), tau], OccupancyParams(bin_deg=1.0, smooth=False)
        )
        low, high = occupancy.tau_min[180, 180], occupancy.tau_max[180, 180]
        centre, half = _brute_force_arc(tau)
        np.testing.assert_allclose(0.5 * (high - low), half, atol=D(0.01))
        offset = (0.5 * (low + high) - centre + np.pi) % (2 * np.pi) - np.pi
        assert abs(offset) < D(0.01)


def test_a_dilated_bin_covers_the_arcs_of_its_neighbours_across_the_wrap() -> None:
    # Two neighbouring bins with arcs on either side of ±180°: the ring bins between and around
    # them take the union, a 40° arc across 180°, not the 320° arc the other way round.
    samples = _samples([(0.5, 0.5, 160.0), (0.5, 0.5, 170.0), (2.5, 0.5, -170.0),
                        (2.5, 0.5, -160.0)])  # fmt: skip
    occupancy = build_occupancy(
        samples, OccupancyParams(bin_deg=1.0, dilation_bins=1, smooth=False)
    )
    ring = occupancy.occupied.copy()
    ring[180, 180] = ring[182, 180] = False
    assert ring.sum() == 13  # the 3×5 block around the two bins, less the two
    width = np.rad2deg(occupancy.tau_max[181, 180] - occupancy.tau_min[181, 180])
    np.testing.assert_allclose(width, 40.0, atol=1e-9)
    inside = _samples([(1.5, 0.5, 180.0), (1.5, 0.5, -165.0), (1.5, 0.5, 165.0)])
    outside = _samples([(1.5, 0.5, 0.0), (1.5, 0.5, 150.0), (1.5, 0.5, -150.0)])
    assert is_valid(occupancy, inside).all()
    assert not is_valid(occupancy, outside).any()


def test_smoothing_averages_twist_centres_the_short_way_round() -> None:
    # Bins at 175° and −175°: their smoothed centres stay near 180°, not near 0°.
    samples = _samples([(0.5, 0.5, 175.0), (1.5, 0.5, -175.0)])
    occupancy = build_occupancy(samples, OccupancyParams(bin_deg=1.0, smooth=True))
    for i1 in (180, 181):
        centre = 0.5 * (occupancy.tau_min[i1, 180] + occupancy.tau_max[i1, 180])
        assert abs(abs((np.rad2deg(centre) + 180) % 360 - 180) - 180) < 5


def test_the_lookups_agree_with_evaluate_on_any_leading_shape() -> None:
    rng = np.random.default_rng(2)
    samples = np.c_[rng.normal(0, 0.6, (500, 2)), rng.uniform(-np.pi, np.pi, 500)]
    occupancy = build_occupancy(
        samples, OccupancyParams(bin_deg=15.0, dilation_bins=1, tau_margin_deg=10, interpolate=True)
    )
    queries = np.c_[rng.normal(0, 1.2, (600, 2)), rng.uniform(-np.pi, np.pi, 600)]
    valid, swing, twist, excess = evaluate(occupancy, queries)
    grid = queries.reshape(20, 30, 3)
    np.testing.assert_array_equal(is_valid(occupancy, grid), valid.reshape(20, 30))
    swing_grid, twist_grid = limit_distances(occupancy, grid)
    np.testing.assert_array_equal(swing_grid, swing.reshape(20, 30))
    np.testing.assert_array_equal(twist_grid, twist.reshape(20, 30))
    np.testing.assert_array_equal(signed_excess(occupancy, grid), excess.reshape(20, 30, 3))
    # Outside means a positive distance, inside none; the signed excess has those sizes.
    assert (~valid).any()
    assert valid.any()
    np.testing.assert_array_equal(np.hypot(swing, twist) > 0, ~valid)
    np.testing.assert_allclose(np.hypot(excess[:, 0], excess[:, 1]), swing, atol=1e-9)
    np.testing.assert_allclose(np.abs(excess[:, 2]), twist, atol=1e-9)


def test_bin_size_has_a_lower_bound_that_keeps_the_paper_setting() -> None:
    # 1e-6 divides 360 (3.6e8 bins a side): building it asked for 921 PiB.
    for tiny in (1e-6, 0.25, float("nan"), 0.0, -1.0):
        with pytest.raises(InputError, match=r"Expected `bin_deg` from 0\.5 to 360 degrees"):
            OccupancyParams(bin_deg=tiny)
    for valid in (MIN_BIN_DEG, 1.0, 15.0, 360.0):
        assert OccupancyParams(bin_deg=valid).n_bins == round(360 / valid)
