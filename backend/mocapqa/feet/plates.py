"""Force-plate contacts as ground truth for the contact detector, and its score against them.

Conventions
-----------
* ``loads`` ``(S, N)``: the force along each of N plates' normals, newtons, positive when
  loaded, one row per analog sample (:func:`mocapqa.io.c3d_plates.read_force_plates`);
  analog sample ``k`` lies ``k / analog_rate`` seconds after point frame 0 and belongs to point
  frame ``k // samples_per_frame``.
* A **plate contact** is a run of samples over :data:`PLATE_THRESHOLD_N`, with breaks up to
  :data:`MAX_BREAK_S` closed and runs under :data:`MIN_LOAD_S` dropped. 20 N is about 3 % of an
  adult's weight: above the unloaded plates' noise and the drift of their offsets (a few newtons
  in the corpus), and reached within a few milliseconds of touch-down, when the vertical force
  rises by 100–400 N per 10 ms.
* **Which foot**: the plate's corners are projected with the markers onto the plate's plane; a
  foot is over the plate in a frame where any of its points lies inside the corners. The
  contact goes to the foot over the plate in at least :data:`OVER_SHARE` of its frames while the
  other foot is over it in under :data:`OTHER_SHARE` (a swing foot crosses a plate in a tenth of
  a stance); otherwise it has no foot (both feet on one plate, or markers missing) and counts
  neither way.
* **Score**: a plate contact is found when a detected contact of the same foot overlaps it
  (recall). A detected contact is judged only when its foot is over an active plate in at least
  half of its frames: it is right when it overlaps a plate contact of its foot, wrong when it
  overlaps none, and not counted when it overlaps only plate contacts with no foot (precision).
  Contacts off the plates are neither. Timing errors are the detected start and end minus the
  plate's onset and offset, milliseconds, for the best-overlapping detected contact of each
  plate contact found; an onset or offset cut by the start or end of the recording is left
  out.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, column_runs
from mocapqa.errors import ShapeError
from mocapqa.feet.contacts import Contact
from mocapqa.feet.points import SIDES, per_foot
from mocapqa.feet.runs import close_short_gaps, drop_short_runs, frames_in

__all__ = [
    "MAX_BREAK_S",
    "MIN_LOAD_S",
    "OTHER_SHARE",
    "OVER_SHARE",
    "PLATE_THRESHOLD_N",
    "PlateContact",
    "PlateScore",
    "over_plates",
    "plate_contacts",
    "score_contacts",
]

PLATE_THRESHOLD_N = 20.0
"""Vertical force over which a plate is loaded, newtons."""
MIN_LOAD_S = 0.02
"""Shortest load kept, seconds (shorter ones are knocks and spikes)."""
MAX_BREAK_S = 0.02
"""Breaks in a load up to this long are closed, seconds."""
OVER_SHARE = 0.5
"""Share of a plate contact's frames its foot must be over the plate."""
OTHER_SHARE = 0.2
"""Share of those frames the other foot may be over the plate."""


@dataclass(frozen=True, slots=True)
class PlateContact:
    """One loading of one plate.

    Parameters
    ----------
    plate : int
        Plate index (0-based).
    foot : {"left", "right"} or None
        The foot on the plate; None when not one foot (see the module notes).
    over : tuple of float
        Share of the contact's point frames the left and the right foot are over the plate.
    start_s, end_s : float
        Onset and offset: first and last sample over the threshold, seconds after point
        frame 0.
    start, end : int
        The point frames holding them (0-based, inclusive).
    cut_start, cut_end : bool
        Whether the load was already on at the first sample, or still on at the last.
    """

    plate: int
    foot: str | None
    over: tuple[float, float]
    start_s: float
    end_s: float
    start: int
    end: int
    cut_start: bool
    cut_end: bool


def over_plates(
    positions: FloatArray,
    corners: FloatArray,
    max_height: float,
    fps: float,
    max_speed: float,
) -> BoolArray:
    """Whether each point stands on each plate: inside its corners (projected on its plane),
    at most ``max_height`` from the plane and slower than ``max_speed``.

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
        Take units (the corners' units); NaN where missing (never over).
    corners : ndarray, shape (N, 4, 3)
        Each plate's corners in order around it.
    max_height : float
        Largest distance from the plate's plane, take units.
    fps : float
        Frames per second.
    max_speed : float
        Take units per second (central differences): a swing foot crossing a plate low
        moves at metres per second.

    Returns
    -------
    ndarray of bool, shape (F, P, N)
    """
    corners = np.asarray(corners, dtype=np.float64)
    if corners.ndim != 3 or corners.shape[1:] != (4, 3):
        raise ShapeError(f"Expected corners of shape (N, 4, 3), got {corners.shape}")
    normals = np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])  # (N, 3)
    edges = np.roll(corners, -1, axis=1) - corners  # (N, 4, 3)
    # Sign of (edge × (point − corner)) · normal per edge: the same for all four inside.
    offsets = positions[:, :, None, None, :] - corners[None, None]  # (F, P, N, 4, 3)
    sides = np.einsum("fpnkc,nc->fpnk", np.cross(edges[None, None], offsets), normals)
    units = normals / np.linalg.norm(normals, axis=-1, keepdims=True)
    heights = np.abs(np.einsum("fpnc,nc->fpn", offsets[:, :, :, 0], units))
    if positions.shape[0] > 1:
        speeds = np.linalg.norm(np.gradient(positions, axis=0), axis=-1) * fps
    else:
        speeds = np.zeros(positions.shape[:2])
    with np.errstate(invalid="ignore"):
        inside: BoolArray = np.all(sides > 0, axis=-1) | np.all(sides < 0, axis=-1)
        on: BoolArray = inside & (heights <= max_height) & (speeds <= max_speed)[:, :, None]
    return on


def plate_contacts(
    loads: FloatArray,
    analog_rate: float,
    samples_per_frame: int,
    over: BoolArray,
    sides: tuple[str, ...],
    threshold_n: float = PLATE_THRESHOLD_N,
) -> list[PlateContact]:
    """The plate contacts of a take, each given to the foot over the plate.

    Parameters
    ----------
    loads : ndarray, shape (S, N)
        Force along each plate's normal, newtons, positive when loaded.
    analog_rate : float
        Samples per second.
    samples_per_frame : int
        Analog samples per point frame.
    over : ndarray of bool, shape (F, P, N)
        From :func:`over_plates`.
    sides : tuple of str
        The foot of each point.
    threshold_n : float, optional
        Newtons.

    Returns
    -------
    list of PlateContact
        By onset, then plate.
    """
    loads = np.asarray(loads, dtype=np.float64)
    n_frames = over.shape[0]
    mask = close_short_gaps(loads > threshold_n, frames_in(MAX_BREAK_S, analog_rate))
    mask = drop_short_runs(mask, frames_in(MIN_LOAD_S, analog_rate))
    plates, first, last = column_runs(mask)
    # Per frame and plate, whether each foot is over it: (F, 2, N).
    feet_over = np.stack(
        [per_foot(over[:, :, n], sides, np.logical_or) for n in range(over.shape[2])], axis=-1
    )
    start = np.minimum(first // samples_per_frame, n_frames - 1)
    end = np.minimum(last // samples_per_frame, n_frames - 1)
    counts = np.cumsum(np.concatenate([np.zeros((1, 2, over.shape[2])), feet_over]), axis=0)
    shares = (counts[end + 1, :, plates] - counts[start, :, plates]) / (end - start + 1)[:, None]
    contacts = []
    for k in range(plates.size):
        left, right = (float(v) for v in shares[k])
        best = int(np.argmax(shares[k]))
        one = shares[k, best] >= OVER_SHARE and shares[k, 1 - best] < OTHER_SHARE
        contacts.append(
            PlateContact(
                plate=int(plates[k]),
                foot=SIDES[best] if one else None,
                over=(round(left, 3), round(right, 3)),
                start_s=float(first[k]) / analog_rate,
                end_s=float(last[k]) / analog_rate,
                start=int(start[k]),
                end=int(end[k]),
                cut_start=bool(first[k] == 0),
                cut_end=bool(last[k] == loads.shape[0] - 1),
            )
        )
    contacts.sort(key=lambda c: (c.start_s, c.plate))
    return contacts


@dataclass(frozen=True, slots=True)
class PlateScore:
    """The contact detector against the plates of one take.

    Parameters
    ----------
    plate_contacts : int
        Plate contacts given to one foot.
    unassigned : int
        Plate contacts with no foot (not counted).
    found : int
        Plate contacts a detected contact of their foot overlaps.
    judged : int
        Detected contacts over an active plate in at least half their frames, and not only
        on plate contacts with no foot.
    right : int
        Of those, the ones overlapping a plate contact of their foot.
    onset_ms, offset_ms : ndarray, shape (K,)
        Detected start (end) minus the plate's onset (offset), milliseconds, signed.
    """

    plate_contacts: int
    unassigned: int
    found: int
    judged: int
    right: int
    onset_ms: FloatArray
    offset_ms: FloatArray

    @property
    def recall(self) -> float:
        """Found over plate contacts (NaN without any)."""
        return self.found / self.plate_contacts if self.plate_contacts else float("nan")

    @property
    def precision(self) -> float:
        """Right over judged (NaN without any)."""
        return self.right / self.judged if self.judged else float("nan")


def _overlap(a0: int, a1: int, b0: int, b1: int) -> int:
    return max(0, min(a1, b1) - max(a0, b0) + 1)


def score_contacts(
    truth: Sequence[PlateContact],
    detected: Sequence[Contact],
    on_plate: BoolArray,
    fps: float,
) -> PlateScore:
    """Score detected foot contacts against plate contacts (see the module notes).

    Parameters
    ----------
    truth : sequence of PlateContact
    detected : sequence of Contact
        Foot contacts (0-based frames, ends inclusive).
    on_plate : ndarray of bool, shape (F, 2)
        Per frame whether the left and the right foot are over an active plate.
    fps : float
        Point frames per second.

    Returns
    -------
    PlateScore
    """
    n_frames = on_plate.shape[0]
    assigned = [t for t in truth if t.foot is not None]
    found = 0
    onsets: list[float] = []
    offsets: list[float] = []
    for t in assigned:
        overlaps = [
            (_overlap(t.start, t.end, c.start, c.end), c) for c in detected if c.foot == t.foot
        ]
        overlaps = [(o, c) for o, c in overlaps if o > 0]
        if not overlaps:
            continue
        found += 1
        _, best = max(overlaps, key=lambda oc: oc[0])
        if not t.cut_start and best.start > 0:
            onsets.append(1000.0 * (best.start / fps - t.start_s))
        if not t.cut_end and best.end < n_frames - 1:
            offsets.append(1000.0 * (best.end / fps - t.end_s))
    judged = right = 0
    for c in detected:
        column = SIDES.index(c.foot)
        if np.mean(on_plate[c.start : c.end + 1, column]) < 0.5:
            continue
        touched = [t for t in truth if _overlap(t.start, t.end, c.start, c.end) > 0]
        if any(t.foot == c.foot for t in touched):
            judged += 1
            right += 1
        elif not touched or any(t.foot is not None for t in touched):
            judged += 1
    return PlateScore(
        plate_contacts=len(assigned),
        unassigned=len(truth) - len(assigned),
        found=found,
        judged=judged,
        right=right,
        onset_ms=np.asarray(onsets),
        offset_ms=np.asarray(offsets),
    )
