"""Findings on synthetic feet: an injected slide, a penetration, a hovering foot, jitter."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from tests.feet.walker import FPS, LEG_CM, stand, walk

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError
from mocapqa.feet.check import check_feet
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.inject import inject_penetration, inject_slide
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import FootPoints

Y_UP = UpAxis(1, 1, "given", (0.0, 0.0, 0.0))


def test_a_clean_walk_has_no_finding() -> None:
    assert check_feet(walk().points).findings == ()


def test_an_injected_3_cm_slide_is_found_on_its_foot_with_its_frames_and_size() -> None:
    walking = walk()
    start, end = walking.stances["right"][2]  # frames 199–279
    positions = inject_slide(walking.points.positions, [2, 3], start, end, (3.0, 0.0), Y_UP)
    report = check_feet(dataclasses.replace(walking.points, positions=positions))
    skates = [f for f in report.findings if f.kind == "skate"]
    assert len(skates) == 1
    skate = skates[0]
    assert skate.foot == "right"
    assert abs(skate.start - start) <= 0.05 * FPS
    assert abs(skate.end - end) <= 2
    assert skate.size == pytest.approx(3.0, abs=0.3)
    assert skate.speed == pytest.approx(3.0 / ((end - start) / FPS), rel=0.15)
    assert start <= skate.peak <= end + 2


def test_a_slide_under_the_threshold_is_not_reported() -> None:
    walking = walk()
    start, end = walking.stances["left"][2]
    positions = inject_slide(walking.points.positions, [0, 1], start, end, (0.0, 1.0), Y_UP)
    report = check_feet(dataclasses.replace(walking.points, positions=positions))
    assert [f for f in report.findings if f.kind == "skate"] == []


def _rolled_over(points: FootPoints, pivot: FloatArray) -> FloatArray:
    """Push-off: the left foot (ankle and toe) turns 25° in pitch about ``pivot`` over frames
    120–199 and stays there."""
    rolled = points.positions.copy()
    frames = np.arange(120, 200)
    angle = np.radians(np.linspace(0.0, 25.0, frames.size))[:, None]
    for k in (0, 1):
        back = rolled[0, k] - pivot
        rolled[frames, k, 0] = (
            pivot[0] + back[0] * np.cos(angle[:, 0]) - back[1] * np.sin(angle[:, 0])
        )
        rolled[frames, k, 1] = (
            pivot[1] + back[0] * np.sin(angle[:, 0]) + back[1] * np.cos(angle[:, 0])
        )
        rolled[200:, k] = rolled[199, k]
    return rolled


def test_a_foot_rolling_over_the_sole_under_its_toe_does_not_skate() -> None:
    # The toe joint sits sole_depth above the floor it rolls on: its sole point stays, the
    # toe joint itself moves forward 2.3 cm.
    points = stand(seconds=2.0)
    params = FeetParams()
    pivot = points.positions[0, 1] - [0.0, params.sole_depth * LEG_CM, 0.0]
    rolled = _rolled_over(points, pivot)
    assert np.ptp(rolled[:, 1, 0]) > 2.0
    report = check_feet(dataclasses.replace(points, positions=rolled), params)
    assert [f for f in report.findings if f.kind == "skate"] == []
    # Read at the joints (no sole below them), the same roll slides.
    flat = dataclasses.replace(params, sole_depth=0.0)
    report = check_feet(dataclasses.replace(points, positions=rolled), flat)
    assert [f.foot for f in report.findings if f.kind == "skate"] == ["left"]


def test_a_foot_rolling_over_its_toe_joint_does_not_skate_without_a_sole_depth() -> None:
    points = stand(seconds=2.0)
    rolled = _rolled_over(points, points.positions[0, 1])
    params = FeetParams(sole_depth=0.0)
    report = check_feet(dataclasses.replace(points, positions=rolled), params)
    assert [f for f in report.findings if f.kind == "skate"] == []


def test_a_penetration_is_found_with_its_depth_and_frames() -> None:
    points = stand(seconds=3.0)
    sunk = inject_penetration(points.positions, [0, 1], 120, 180, 2.5, Y_UP)
    report = check_feet(dataclasses.replace(points, positions=sunk))
    found = [f for f in report.findings if f.kind == "penetration"]
    assert len(found) == 1
    assert found[0].foot == "left"
    assert found[0].size == pytest.approx(2.5, abs=0.01)
    assert abs(found[0].start - 120) <= 2
    assert abs(found[0].end - 180) <= 2


def test_a_foot_hovering_still_above_the_floor_is_floating() -> None:
    points = stand(seconds=3.0)
    hover = points.positions.copy()
    lift = np.zeros(hover.shape[0])
    lift[100:140] = np.linspace(0.0, 9.0, 40)  # raised over a third of a second
    lift[140:240] = 9.0  # held still 9 cm up for 0.83 s
    lift[240:280] = np.linspace(9.0, 0.0, 40)
    hover[:, 2:4, 1] += lift[:, None]
    report = check_feet(dataclasses.replace(points, positions=hover))
    floating = [f for f in report.findings if f.kind == "floating"]
    assert [f.foot for f in floating] == ["right"]
    assert floating[0].start <= 150
    assert floating[0].end >= 230
    assert floating[0].size == pytest.approx(9.0, abs=0.5)


def test_noise_on_a_planted_foot_is_jitter_with_its_size() -> None:
    points = stand(seconds=3.0)
    rng = np.random.default_rng(7)
    noisy = points.positions.copy()
    noisy[:, 0:2] += rng.normal(0.0, 0.5, size=noisy[:, 0:2].shape)  # 0.5 cm per axis
    report = check_feet(dataclasses.replace(points, positions=noisy))
    jitter = [f for f in report.findings if f.kind == "jitter"]
    assert [f.foot for f in jitter] == ["left"]
    assert jitter[0].size == pytest.approx(0.5 * np.sqrt(3.0), rel=0.1)
    assert jitter[0].size > 0.004 * LEG_CM


def test_injections_check_their_frames() -> None:
    points = stand(seconds=1.0)
    with pytest.raises(InputError, match="Expected 0 ≤ start ≤ end < 120, got 50 and 200"):
        inject_slide(points.positions, [0], 50, 200, (1.0, 0.0), Y_UP)
