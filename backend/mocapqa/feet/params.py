"""The parameters of the feet checks: one frozen dataclass, lengths in leg lengths.

Every length threshold is a fraction of the take's leg length (hip → knee → ankle), so one set
of values suits centimetres, metres, inches and unknown units, adults and children; the
comments give each in centimetres for a 90 cm leg (a 1.83 m adult). Times are seconds, so the
values hold at any frame rate. ``plant_height``, ``plant_speed``, ``sole_depth``,
``slide_height`` and ``skate_travel`` are the values ``mocapqa bench feet`` chose on the fit
takes of the corpus; the others were set by hand on the fit takes and synthetic feet
(docs/feet.md, "Thresholds and figures"). The event window is off here: it was chosen on
force plates, for marker takes (:data:`mocapqa.feet.markers.MARKER_PARAMS`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from mocapqa.errors import OptionError

__all__ = ["FeetParams"]


@dataclass(frozen=True, slots=True)
class FeetParams:
    """Thresholds of the up-axis, floor, contact and finding checks.

    Parameters
    ----------
    contact_height : float
        A point enters a contact below this height above its own stance level, leg lengths
        (0.04: 3.6 cm).
    release_height : float
        It stays in contact while below this height (hysteresis), leg lengths (0.07: 6.3 cm).
    contact_speed : float
        A point enters a contact below this speed, leg lengths per second (0.3: 27 cm/s).
    release_speed : float
        It stays in contact while below this speed, leg lengths per second (0.6: 54 cm/s).
    speed_window_s : float
        Window of the moving average before speeds are taken, seconds.
    min_contact_s : float
        Shortest contact kept, seconds.
    max_gap_s : float
        Breaks in a contact up to this long are closed, seconds.
    stance_percentile : float
        A point still in fewer than 5 frames rests at this percentile of its heights (0–100);
        the others at the median of their still heights in the densest window half
        ``contact_height`` tall.
    skate_travel : float
        Horizontal travel of a planted foot reported as skate, leg lengths (0.014: 1.26 cm).
    skate_window_s : float
        Travel is measured over at most this long, seconds: a foot that creeps by small
        repositionings through a stance of several seconds does not add them up.
    plant_height : float
        A contact's point counts toward its travel while within this height of its lowest
        height in the contact, leg lengths (0.006: 0.54 cm): a heel rising at push-off
        rolls, it does not slide.
    plant_speed : float
        The travel counts the frames where the pivot is slower than this, leg lengths per
        second (0.1: 9 cm/s), or than 1.5 times the contact's median pivot speed.
    sole_depth : float
        The sole lies this far below the lowest foot point at rest, leg lengths (0.06:
        5.4 cm): the skate check reads the velocity of the sole under each point, each
        point's height above the floor plus this below it (:mod:`mocapqa.feet.sole`).
    sole_pivot : bool
        Whether the skate check reads the sole under the points (True) or the points
        themselves (False: the pivot the foot lock holds, :mod:`mocapqa.feet.lock`).
    slide_height : float
        The skate check also reads phases where every point of a foot is below this height
        above its stance level while moving too fast for a contact, leg lengths (0.02:
        1.8 cm; 0: only contacts; :mod:`mocapqa.feet.slides`) ...
    slide_speed : float
        ... and slower than this, leg lengths per second (a swing at floor level is faster).
    event_before_s, event_after_s : float
        Each contact's first frame moves to the heel's impact, and its last to the toe's
        push-off, within this long before and after them, seconds (0 and 0: not moved;
        :mod:`mocapqa.feet.events`).
    penetration_depth : float
        Depth below the floor reported as penetration, leg lengths (0.015: 1.35 cm).
    float_height : float
        Highest a still foot may hover above the floor to count as floating rather than
        lifted, leg lengths (0.15: 13.5 cm).
    min_float_s : float
        Shortest floating phase reported, seconds.
    jitter_noise : float
        Frame-to-frame noise (RMS) of a planted foot reported as jitter, leg lengths
        (0.004: 3.6 mm).
    floor_tilt_deg : float
        A floor plane steeper than this is tilted (when it also rises by ``floor_rise``).
    floor_rise : float
        Height change of the floor plane across the stance area above which a steeper-than-
        ``floor_tilt_deg`` plane is reported tilted, leg lengths (0.02: 1.8 cm).
    floor_drift : float
        Change of the floor level between segments of the take above which the floor is
        reported moving, leg lengths (0.02: 1.8 cm).
    floor_segment_s : float
        Length of the segments the floor level is measured in, seconds.
    """

    contact_height: float = 0.04
    release_height: float = 0.07
    contact_speed: float = 0.3
    release_speed: float = 0.6
    speed_window_s: float = 0.1
    min_contact_s: float = 0.1
    max_gap_s: float = 0.05
    stance_percentile: float = 5.0
    skate_travel: float = 0.014
    skate_window_s: float = 1.0
    plant_height: float = 0.006
    plant_speed: float = 0.1
    sole_depth: float = 0.06
    sole_pivot: bool = True
    slide_height: float = 0.02
    slide_speed: float = 1.0
    event_before_s: float = 0.0
    event_after_s: float = 0.0
    penetration_depth: float = 0.015
    float_height: float = 0.15
    min_float_s: float = 0.25
    jitter_noise: float = 0.004
    floor_tilt_deg: float = 0.25
    floor_rise: float = 0.02
    floor_drift: float = 0.02
    floor_segment_s: float = 2.0

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, int | float) and value == value and value >= 0):
                raise OptionError(f.name, f"Expected a number ≥ 0, got {value!r}")
        if self.release_height < self.contact_height:
            raise OptionError(
                "release_height",
                f"Expected ≥ contact_height ({self.contact_height}), got {self.release_height}",
            )
        if self.release_speed < self.contact_speed:
            raise OptionError(
                "release_speed",
                f"Expected ≥ contact_speed ({self.contact_speed}), got {self.release_speed}",
            )
        if self.stance_percentile > 100:
            raise OptionError("stance_percentile", f"Expected 0–100, got {self.stance_percentile}")
