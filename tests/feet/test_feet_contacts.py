"""Contacts with hysteresis on a synthetic walk whose planted phases are known."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from tests.feet.walker import FPS, stand, walk

from mocapqa.errors import OptionError
from mocapqa.feet.check import check_feet
from mocapqa.feet.contacts import point_contact_mask
from mocapqa.feet.params import FeetParams


def test_each_planted_phase_of_a_walk_is_one_contact_at_the_right_frames() -> None:
    walking = walk()
    report = check_feet(walking.points)
    for side in ("left", "right"):
        found = [(c.start, c.end) for c in report.contacts if c.foot == side]
        truth = walking.stances[side]
        assert len(found) == len(truth)
        for (start, end), (true_start, true_end) in zip(found, truth, strict=True):
            # The landing slows the foot over its last frames of swing: a contact may start
            # up to 0.05 s late; it ends within 2 frames of the lift-off.
            assert true_start <= start <= true_start + 0.05 * FPS
            assert abs(end - true_end) <= 2
    assert [c.foot for c in report.contacts][:4] == ["left", "right", "right", "left"]
    assert all(0.5 <= c.confidence <= 1.0 for c in report.contacts)


def test_point_contacts_name_their_part() -> None:
    report = check_feet(walk(seconds=2.0).points)
    assert {c.part for c in report.point_contacts} == {"ankle", "toe"}
    assert all(c.part is None for c in report.contacts)


def test_a_foot_standing_still_is_one_contact_over_the_whole_take() -> None:
    report = check_feet(stand(seconds=2.0))
    assert [(c.foot, c.start, c.end) for c in report.contacts] == [
        ("left", 0, 239), ("right", 0, 239),
    ]  # fmt: skip
    assert all(c.confidence == pytest.approx(1.0) for c in report.contacts)
    assert report.findings == ()


def test_hysteresis_keeps_a_contact_through_a_wobble_between_the_two_heights() -> None:
    leg = 90.0
    elevations = np.zeros((60, 1))
    elevations[20:30] = 0.05 * leg  # above contact_height (0.04), under release (0.07)
    speeds = np.zeros((60, 1))
    params = FeetParams()
    assert point_contact_mask(elevations, speeds, FPS, leg, params).all()
    elevations[20:30] = 0.08 * leg  # above the release height: the contact breaks
    mask = point_contact_mask(elevations, speeds, FPS, leg, params)[:, 0]
    assert mask[:20].all()
    assert not mask[20:30].any()
    assert mask[30:].all()


def test_contacts_shorter_than_the_minimum_are_dropped() -> None:
    leg = 90.0
    elevations = np.full((60, 1), 0.2 * leg)
    elevations[10:15] = 0.0  # 5 frames: under min_contact_s (0.1 s = 12 frames at 120 fps)
    elevations[30:50] = 0.0
    mask = point_contact_mask(elevations, np.zeros((60, 1)), FPS, leg)[:, 0]
    assert np.flatnonzero(mask).tolist() == list(range(30, 50))


def test_a_missing_keypoint_is_never_in_contact() -> None:
    points = stand(seconds=1.0)
    gappy = points.positions.copy()
    gappy[40:80, 0:2] = np.nan  # the left foot undetected
    report = check_feet(dataclasses.replace(points, positions=gappy))
    left = [(c.start, c.end) for c in report.contacts if c.foot == "left"]
    assert left[0][1] < 40
    assert left[-1][0] >= 80


def test_params_refuse_loose_thresholds_below_strict_ones() -> None:
    with pytest.raises(OptionError, match="release_height"):
        FeetParams(contact_height=0.08, release_height=0.07)
    with pytest.raises(OptionError, match="skate_travel"):
        FeetParams(skate_travel=-1.0)
