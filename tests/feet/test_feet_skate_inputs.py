"""The skate check's inputs: the sole under the foot points, the low phases a fast slide leaves,
and the per-run medians and maxima it reads."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from tests.feet.walker import FPS, LEG_CM, stand

from mocapqa.feet.check import check_feet
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.inject import inject_slide
from mocapqa.feet.params import FeetParams
from mocapqa.feet.runs import run_argmax, run_median
from mocapqa.feet.slides import skate_masks
from mocapqa.feet.sole import sole_sweep

Y_UP = UpAxis(1, 1, "given", (0.0, 0.0, 0.0))


def _rotation(omega: np.ndarray, centre: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Velocity of ``point`` on a body turning at ``omega`` (rad/s) about ``centre``."""
    return np.cross(omega, point - centre)


@pytest.mark.parametrize("up", [Y_UP, UpAxis(2, -1, "given", (0.0, 0.0, 0.0))])
def test_the_sole_under_a_foot_rolling_about_a_floor_point_moves_only_vertically(
    up: UpAxis,
) -> None:
    upward = np.zeros(3)
    upward[up.axis] = up.sign
    forward = np.roll(upward, 1)
    rear = 8.0 * upward
    toe = 15.0 * forward + 2.0 * upward
    pivot = 15.0 * forward  # on the floor under the toe
    omega = 1.5 * np.cross(upward, forward)  # pitch
    v_rear, v_toe = _rotation(omega, pivot, rear), _rotation(omega, pivot, toe)
    sweep = sole_sweep((toe - rear)[None], (v_toe - v_rear)[None], up)[0]
    for velocity, height in ((v_rear, 8.0), (v_toe, 2.0)):
        sole = velocity - height * sweep
        horizontal = sole - (sole @ upward) * upward
        assert np.linalg.norm(horizontal) < 1e-9
        assert np.linalg.norm(velocity - (velocity @ upward) * upward) > 1.0


def test_a_sliding_or_yawing_level_foot_has_no_sole_correction() -> None:
    rear, toe = np.array([0.0, 3.0, 0.0]), np.array([15.0, 3.0, 0.0])
    slide = np.array([3.0, 0.0, 1.0])
    assert np.allclose(sole_sweep((toe - rear)[None], (slide - slide)[None], Y_UP), 0.0)
    yaw = np.array([0.0, 2.0, 0.0])
    change = _rotation(yaw, rear, toe) - _rotation(yaw, rear, rear)
    assert np.allclose(sole_sweep((toe - rear)[None], change[None], Y_UP), 0.0)


def test_missing_or_coincident_points_give_no_sweep() -> None:
    span = np.array([[np.nan, 1.0, 0.0], [0.0, 0.0, 0.0]])
    change = np.array([[1.0, 1.0, 1.0], [1.0, 0.0, 0.0]])
    assert np.array_equal(sole_sweep(span, change, Y_UP), np.zeros((2, 3)))


def test_a_low_fast_phase_joins_the_skate_masks_and_a_lifted_foot_does_not() -> None:
    n = 40
    elevations = np.zeros((n, 4))
    speeds = np.zeros((n, 4))
    point_mask = np.ones((n, 4), dtype=bool)
    point_mask[15:25, :2] = False  # the left foot's contact is broken ...
    speeds[15:25, :2] = 0.5 * LEG_CM  # ... by a slide at floor level
    point_mask[15:25, 2:] = False  # the right foot is lifted
    elevations[15:25, 2] = 0.2 * LEG_CM
    foot_mask = np.stack([point_mask[:, 0], point_mask[:, 2]], axis=1)
    sides = ("left", "left", "right", "right")
    params = FeetParams()
    points, feet = skate_masks(elevations, speeds, point_mask, foot_mask, sides, FPS, LEG_CM,
                               params)  # fmt: skip
    assert feet[:, 0].all()
    assert points[:, :2].all()
    assert not feet[15:25, 1].any()
    assert not points[15:25, 2:].any()
    # Too fast for a slide (a swing at floor level), or no slide phase asked for.
    fast = np.where(speeds > 0, 2.0 * params.slide_speed * LEG_CM, 0.0)
    _, feet = skate_masks(elevations, fast, point_mask, foot_mask, sides, FPS, LEG_CM, params)
    assert not feet[15:25, 0].any()
    off = dataclasses.replace(params, slide_height=0.0)
    points, feet = skate_masks(elevations, speeds, point_mask, foot_mask, sides, FPS, LEG_CM, off)
    assert np.array_equal(feet, foot_mask)
    assert np.array_equal(points, point_mask)


def test_a_slide_fast_enough_to_undo_a_short_contact_is_still_a_skate() -> None:
    # The left foot is down for 0.25 s (frames 40–69) and slides 8 cm meanwhile: 32 cm/s,
    # faster than contact_speed, so no contact forms.
    points = stand(seconds=1.0)
    lifted = points.positions.copy()
    lifted[:40, :2, 1] += 20.0
    lifted[70:, :2, 1] += 20.0
    moved = inject_slide(lifted, [0, 1], 40, 69, (8.0, 0.0), Y_UP)
    slid = dataclasses.replace(points, positions=moved)
    params = FeetParams()
    assert params.contact_speed * LEG_CM < 8.0 / (30 / FPS)
    report = check_feet(slid, params)
    assert not [c for c in report.contacts if c.foot == "left" and c.start <= 55 <= c.end]
    skates = [f for f in report.findings if f.kind == "skate" and f.foot == "left"]
    assert len(skates) == 1
    assert (
        2.0 < skates[0].size <= 8.5
    )  # the frames low enough: the 20-cm lift, smoothed, covers the ends
    assert skates[0].start <= 55 <= skates[0].end
    without = check_feet(slid, dataclasses.replace(params, slide_height=0.0))
    assert not [f for f in without.findings if f.kind == "skate" and f.foot == "left"]


def test_run_median_and_run_argmax_match_a_loop() -> None:
    rng = np.random.default_rng(3)
    run_index = np.sort(rng.integers(0, 40, size=600))
    run_index = np.unique(run_index, return_inverse=True)[1]
    values = rng.normal(size=600).round(1)
    values[rng.random(600) < 0.1] = np.nan
    values[rng.random(600) < 0.05] = np.inf
    medians = run_median(values, run_index)
    tops, where = run_argmax(values, run_index, int(run_index.max()) + 1)
    for k in range(int(run_index.max()) + 1):
        members = values[run_index == k]
        finite = np.sort(members[np.isfinite(members)])
        expected = finite[(finite.size - 1) // 2] if finite.size else np.nan
        assert np.array_equal(medians[k], expected, equal_nan=True)
        filled = np.where(np.isfinite(members), members, -np.inf)
        assert tops[k] == filled.max()
        assert where[k] == np.flatnonzero(run_index == k)[int(np.argmax(filled))]
