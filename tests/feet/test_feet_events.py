"""Contact edges moved to the heel's impact and the toe's push-off (marker takes)."""

from __future__ import annotations

import dataclasses

import numpy as np
from tests.feet.walker import FPS, stand

from mocapqa.feet.events import event_signals, refine_contact_edges
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.params import FeetParams

Y_UP = UpAxis(1, 1, "given", (0.0, 0.0, 0.0))
WINDOW = FeetParams(event_before_s=0.05, event_after_s=0.05)


def _step(impact: int, lift: int) -> np.ndarray:
    """Both feet planted except the left: its heel falls at 1 m/s until ``impact`` and stops;
    the foot sets off forward at 1 m/s from ``lift``."""
    positions = stand(seconds=2.0).positions.copy()
    frames = np.arange(positions.shape[0])
    fall = np.clip(impact - frames, 0, None) / FPS * 100.0  # cm above rest
    positions[:, 0, 1] += fall
    positions[:, 1, 1] += fall * 0.2
    push = np.clip(frames - lift, 0, None) / FPS * 100.0
    positions[:, 0, 0] += push
    positions[:, 1, 0] += push
    return positions


def test_the_signals_peak_at_the_impact_and_the_push_off() -> None:
    strike, push = event_signals(_step(100, 170), ("left", "left", "right", "right"), Y_UP, FPS)
    assert np.isnan(strike[0]).all()
    assert np.isnan(push[-1]).all()
    assert int(np.nanargmax(strike[:, 0])) == 100
    assert int(np.nanargmax(push[:, 0])) == 170
    assert np.nanmax(np.abs(strike[:, 1])) == 0.0


def test_edges_move_to_the_events_within_the_window_only() -> None:
    positions = _step(100, 170)
    sides = ("left", "left", "right", "right")
    mask = np.zeros((positions.shape[0], 2), dtype=bool)
    mask[104:166, 0] = True  # detected 4 frames late, ending 4 frames early
    mask[:, 1] = True
    refined = refine_contact_edges(mask, positions, sides, Y_UP, FPS, WINDOW)
    left = np.flatnonzero(refined[:, 0])
    assert (left[0], left[-1]) == (100, 170)
    assert refined[:, 1].all()
    # Outside the window (0.02 s = 2 frames here) nothing is found: edges stay.
    narrow = dataclasses.replace(WINDOW, event_before_s=0.02, event_after_s=0.02)
    stays = refine_contact_edges(mask, positions, sides, Y_UP, FPS, narrow)
    assert np.array_equal(stays, mask)
    off = refine_contact_edges(mask, positions, sides, Y_UP, FPS, FeetParams())
    assert np.array_equal(off, mask)


def test_an_edge_never_reaches_into_the_next_contact_of_its_foot() -> None:
    positions = _step(100, 170)
    sides = ("left", "left", "right", "right")
    mask = np.zeros((positions.shape[0], 2), dtype=bool)
    mask[60:98, 0] = True  # the impact at 100 lies after this contact's end ...
    mask[104:166, 0] = True  # ... and before the next one's start
    refined = refine_contact_edges(mask, positions, sides, Y_UP, FPS, WINDOW)
    runs = np.flatnonzero(np.diff(np.r_[0, refined[:, 0].astype(int), 0]))
    starts, ends = runs[::2], runs[1::2] - 1
    assert len(starts) == 2
    assert ends[0] < starts[1] - 1
    assert starts[1] == 100
