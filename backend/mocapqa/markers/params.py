"""The parameters of the marker checks: one frozen dataclass of named thresholds.

Lengths are millimetres and are converted to the take's unit (:func:`unit_scale`), so one set
of values suits takes in metres, centimetres, millimetres and inches; a take in an unknown unit
is read as millimetres. Times are seconds, so the values hold at any frame rate.
``swap_misfit``, ``swap_gain`` and ``swap_held`` are the grid point
:func:`mocapqa_bench.markers.choose` picks on the bench files; the others were set by hand on
them (docs/markers.md, "Thresholds and figures").
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from mocapqa.errors import OptionError

__all__ = ["MM_PER_UNIT", "MarkerParams", "unit_scale"]

MM_PER_UNIT: dict[str, float] = {"m": 1000.0, "cm": 10.0, "mm": 1.0, "in": 25.4}
"""Millimetres per take unit; any other unit is read as millimetres."""


def unit_scale(length_unit: str) -> float:
    """Take units per millimetre (``1 / MM_PER_UNIT``; 1 for an unknown unit)."""
    return 1.0 / MM_PER_UNIT.get(length_unit, 1.0)


@dataclass(frozen=True, slots=True)
class MarkerParams:
    """Thresholds of the gap, spike, segment, swap, label and static-marker checks.

    Parameters
    ----------
    gap_warning_s : float
        Gaps at least this long are warnings (shorter ones are info), seconds.
    gap_error_s : float
        Gaps at least this long are errors, seconds.
    spike_ratio : float
        A frame is a spike candidate when its acceleration departs from the mean of its two
        neighbours' by more than this many robust spreads (1.4826 × MAD) of the marker's own
        departures above their median.
    spike_min_offset : float
        … and by at least ``3 · fps²`` times this, mm: the departure of a single sample
        this far off its smooth path (so sensor noise of a marker that barely moves is not
        flagged, at any frame rate).
    spike_misfit : float
        Where a marker has rigid mates, a spike must also raise its misfit against them by
        this many tolerances above the 3 frames either side.
    spike_max_frames : int
        Runs of flagged frames longer than this (after merging runs 2 frames apart) are not
        spikes (a jump that persists, or real fast motion), frames.
    rigid_spread : float
        A marker pair is rigid (rides on one segment) when the spread of its distance
        (10th to 90th percentile, over frames where both are visible) is at most this …, mm.
    rigid_relative : float
        … plus this fraction of its median distance.
    rigid_min_visible : float
        A pair counts only when both markers are visible together on at least this share of
        the sampled frames (0–1).
    segment_frames : int
        At most this many frames, evenly spaced, are sampled to infer the rigid pairs.
    max_mates : int
        Each marker's swap test uses its this-many most rigid mates …
    mate_score : float
        … among the partners whose spread is at most this many times the rigid threshold
        (a looser pair still tells a swap: its tolerance grows with its spread).
    neighbours : int
        Besides its rigid mates, each marker may swap with its this-many nearest markers
        (by median distance).
    tolerance_floor : float
        Smallest tolerance of a rigid distance in the swap test, mm.
    swap_misfit : float
        A marker is misplaced at a frame when the median of its rigid distances' departures
        exceeds this many tolerances (the pair's half spread, at least ``tolerance_floor``).
    swap_gain : float
        An exchange of two labels explains a frame when it lowers both markers' misfits
        below ``swap_misfit`` and below this fraction of their misfits before.
    swap_cross : float
        Crossing cue: at a swap's first frame each marker is nearer the other's previous
        position than this fraction of its own jump.
    swap_held : float
        Boundary test: a swap is rejected when, at its first frame or its release, both
        labels keep their own trajectories over the ``swap_window`` frames either side:
        at each frame, the two labels' positions miss the other's constant-velocity
        prediction by more than their own, summed, by over this fraction of the pair's
        median distance (two labels well apart cannot exchange without a jump).
    swap_window : int
        Frames either side of a swap's boundary the boundary test reads.
    swap_report : float
        Swaps with less confidence than this are not reported (0–1).
    swap_confidence : float
        Swaps with at least this confidence are applied by ``--apply confident`` (0–1).
    static_std : float
        A marker whose positions vary by less than this (root of the summed per-axis
        variances) is static, mm …
    moving_std : float
        … when the take's median marker varies by more than this, mm.
    """

    gap_warning_s: float = 0.1
    gap_error_s: float = 0.5
    spike_ratio: float = 30.0
    spike_min_offset: float = 15.0
    spike_misfit: float = 0.5
    spike_max_frames: int = 6
    rigid_spread: float = 8.0
    rigid_relative: float = 0.03
    rigid_min_visible: float = 0.5
    segment_frames: int = 600
    max_mates: int = 6
    mate_score: float = 2.0
    neighbours: int = 3
    tolerance_floor: float = 3.0
    swap_misfit: float = 2.5
    swap_gain: float = 0.5
    swap_cross: float = 0.5
    swap_held: float = 0.25
    swap_window: int = 2
    swap_report: float = 0.5
    swap_confidence: float = 0.8
    static_std: float = 1.0
    moving_std: float = 20.0

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, int | float) and value == value and value >= 0):
                raise OptionError(f.name, f"Expected a number ≥ 0, got {value!r}")
        for name in ("rigid_min_visible", "swap_gain", "swap_report", "swap_confidence"):
            if getattr(self, name) > 1:
                raise OptionError(name, f"Expected 0–1, got {getattr(self, name)}")
        if self.gap_error_s < self.gap_warning_s:
            raise OptionError(
                "gap_error_s",
                f"Expected ≥ gap_warning_s ({self.gap_warning_s}), got {self.gap_error_s}",
            )
        for name in ("segment_frames", "spike_max_frames", "swap_window"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 1:
                raise OptionError(name, f"Expected an integer ≥ 1, got {getattr(self, name)!r}")
