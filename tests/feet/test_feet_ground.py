"""Up axis and floor on synthetic feet: axes and signs, floor level, tilt and drift."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from tests.feet.walker import LEG_CM, reaxed, stand, walk

from mocapqa.errors import ShapeError
from mocapqa.feet.check import check_feet
from mocapqa.feet.floor import column_percentile, stance_levels
from mocapqa.feet.points import FootPoints


@pytest.mark.parametrize(
    ("order", "signs", "label"),
    [
        ((0, 1, 2), (1, 1, 1), "Y"),
        ((0, 2, 1), (1, 1, 1), "Z"),  # Y-up data stored Z-up
        ((0, 1, 2), (1, -1, 1), "-Y"),  # Y pointing down (MediaPipe, images)
        ((1, 0, 2), (1, 1, 1), "X"),
    ],
)
def test_the_up_axis_of_a_walk_is_found_with_its_sign(
    order: tuple[int, int, int], signs: tuple[float, ...], label: str
) -> None:
    report = check_feet(reaxed(walk().points, order, signs))
    assert report.up.label == label
    assert report.up.method == "feet and body"


def test_without_a_pelvis_the_feet_give_axis_and_sign() -> None:
    points = dataclasses.replace(reaxed(walk().points, (0, 2, 1), (1, 1, -1)), pelvis=None)
    report = check_feet(points)
    assert report.up.label == "-Z"
    assert report.up.method == "feet"


def test_standing_still_the_body_decides_the_up_axis() -> None:
    report = check_feet(reaxed(stand(), (2, 0, 1), (1, 1, 1)))
    assert report.up.label == "Z"
    assert report.up.method == "body"


def test_the_floor_is_the_lowest_stance_level_and_each_point_keeps_its_offset() -> None:
    points = walk().points
    lifted = dataclasses.replace(points, positions=points.positions + np.array([0.0, 30.0, 0.0]))
    report = check_feet(lifted)
    assert report.floor.level == pytest.approx(32.0, abs=1e-9)  # toes 2 cm above, +30
    assert report.floor.point_offsets == pytest.approx([6.0, 0.0, 6.0, 0.0], abs=1e-9)
    assert report.floor.tilt_deg == pytest.approx(0.0, abs=0.01)
    assert not report.floor.tilted
    assert not report.floor.moving


def test_a_tilted_floor_is_reported_not_levelled() -> None:
    points = walk(seconds=8.0).points
    slope = np.tan(np.radians(3.0))
    raised = points.positions.copy()
    raised[..., 1] += slope * raised[..., 0]
    assert points.pelvis is not None
    pelvis = points.pelvis + np.outer(slope * points.pelvis[:, 0], [0.0, 1.0, 0.0])
    report = check_feet(dataclasses.replace(points, positions=raised, pelvis=pelvis))
    assert report.floor.tilted
    assert report.floor.tilt_deg == pytest.approx(3.0, abs=0.2)
    assert report.floor.rise == pytest.approx(slope * 7.0 * 132.0, rel=0.25)  # ~7 strides
    assert not report.floor.moving


def test_a_floor_that_drops_half_way_through_a_take_in_place_is_moving() -> None:
    points = stand(seconds=6.0)
    moved = points.positions.copy()
    moved[moved.shape[0] // 2 :, :, 1] -= 4.0
    report = check_feet(dataclasses.replace(points, positions=moved))
    assert report.floor.tilt_deg is None  # the feet never leave one spot
    assert report.floor.moving
    assert report.floor.drift == pytest.approx(4.0, abs=0.05)
    levels = [level for _, _, level in report.floor.segments]
    assert levels[0] - levels[-1] == pytest.approx(4.0, abs=0.05)


def test_stance_levels_keep_the_majority() -> None:
    # Point 0: mostly at 0, sunk to -5 a fifth of the time, held up at 20 a fifth of the time.
    point = np.r_[np.full(60, 0.0), np.full(20, -5.0), np.full(20, 20.0)]
    heights = np.stack([point, np.linspace(5.0, 10.0, 100)], axis=1)
    static = np.zeros_like(heights, dtype=bool)
    static[:, 0] = True
    levels = stance_levels(heights, static, 5.0, 2.0)
    assert levels[0] == 0.0
    # Point 1 is never still: the 5th percentile of all its heights.
    assert levels[1] == pytest.approx(np.percentile(heights[:, 1], 5.0))


def test_column_percentile_matches_numpy_on_the_masked_rows() -> None:
    rng = np.random.default_rng(3)
    values = rng.normal(size=(40, 5))
    mask = rng.random((40, 5)) > 0.4
    mask[:, 4] = False
    got = column_percentile(values, mask, 37.0)
    for j in range(4):
        assert got[j] == pytest.approx(np.percentile(values[mask[:, j], j], 37.0))
    assert np.isnan(got[4])


def test_foot_points_refuse_a_foot_without_points_and_a_bad_leg() -> None:
    points = walk(seconds=1.0).points
    with pytest.raises(ShapeError, match="Expected one or two points on the right foot"):
        FootPoints(points.positions[:, :2], ("left", "left"), ("ankle", "toe"), ("a", "b"),
                   120.0, LEG_CM)  # fmt: skip
    with pytest.raises(ShapeError, match=r"Expected `leg_length` > 0, got 0"):
        dataclasses.replace(points, leg_length=0.0)
