"""``mocapqa bench feet``, force plates: the contact detector scored against the contacts the
force plates of the corpus' C3D gait trials measure, the contact parameters chosen leaving each
trial out."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import BoolArray
from mocapqa.errors import InputError
from mocapqa.feet.check import check_feet
from mocapqa.feet.markers import marker_foot_points
from mocapqa.feet.params import FeetParams
from mocapqa.feet.plates import (
    PlateContact,
    PlateScore,
    over_plates,
    plate_contacts,
    score_contacts,
)
from mocapqa.feet.points import FootPoints, per_foot
from mocapqa.io.c3d import read_c3d
from mocapqa.io.c3d_plates import read_force_plates

__all__ = [
    "EVENT_WINDOWS",
    "MARKER_GRID",
    "PLATE_HEIGHT",
    "PLATE_SPEED",
    "PlateRow",
    "PlateTrial",
    "marker_params_by_leave_one_out",
    "plate_trial",
    "plate_trials",
    "score_plate_trial",
]

PLATE_HEIGHT = 0.1
"""A foot point stands on a plate within this distance of its plane, leg lengths (9 cm)."""
PLATE_SPEED = 1.0
"""... and slower than this, leg lengths per second (a swing foot crossing a plate low moves
at several)."""
EVENT_WINDOWS = ((0.0, 0.0), (0.04, 0.02), (0.04, 0.04), (0.08, 0.04))
"""``(event_before_s, event_after_s)`` tried: contact edges as detected, or moved to the heel's
impact and the toe's push-off within that window (:mod:`mocapqa.feet.events`)."""
MARKER_GRID: tuple[dict[str, Any], ...] = tuple(
    {
        "contact_speed": cs,
        "release_speed": rs,
        "contact_height": ch,
        "release_height": rh,
        "speed_window_s": w,
        "event_before_s": before,
        "event_after_s": after,
    }
    for before, after in EVENT_WINDOWS
    for w in (0.1, 0.05)
    for ch in (0.04, 0.06)
    for rh in (0.07, 0.1, 0.15)
    for cs in (0.3, 0.5, 0.8)
    for rs in (0.6, 0.8, 1.0)
    if rs >= cs and rh >= ch
)
"""Contact parameters tried on the force-plate trials (FeetParams' defaults first). Release
speeds stop at 1 leg/s: at 1.5–2 the swing of a slow step no longer breaks the contact
(``Eb015pr``'s left foot, never on a plate, went from 4 contacts to 2), which the plates
cannot see."""


@dataclass(frozen=True, slots=True)
class PlateTrial:
    """A C3D trial with force plates, ready to score the contact detector against.

    Parameters
    ----------
    name : str
        Path inside the corpus.
    plates : int
        Plates with a signal (not flat).
    points : FootPoints or None
        The foot markers; None when the take has none usable (``note`` says why).
    truth : tuple of PlateContact
        The plate contacts, each with its foot or None.
    on_plate : ndarray of bool, shape (F, 2), or None
        Per frame whether the left and the right foot stand on an active plate.
    note : str
        Why the trial cannot be scored, "" when it can.
    """

    name: str
    plates: int
    points: FootPoints | None
    truth: tuple[PlateContact, ...]
    on_plate: BoolArray | None
    note: str


def plate_trial(path: Path, name: str | None = None) -> PlateTrial | None:
    """The plate contacts of a C3D file and its foot markers; None without active plates.

    Raises
    ------
    InputError
        If the file cannot be read.
    """
    plates = read_force_plates(path)
    active = [p for p in plates.plates if not p.flat]
    label = name or path.name
    if not active:
        return None
    try:
        points = marker_foot_points(read_c3d(path).points)
    except InputError as e:
        return PlateTrial(label, len(active), None, (), None, getattr(e, "message", str(e)))
    leg = points.leg_length
    over = over_plates(
        points.positions,
        np.stack([p.corners for p in active]),
        PLATE_HEIGHT * leg,
        points.fps,
        PLATE_SPEED * leg,
    )
    loads = np.stack([p.load for p in active], axis=1)
    truth = plate_contacts(loads, plates.analog_rate, plates.samples_per_frame, over, points.sides)
    truth = [dataclasses.replace(t, plate=active[t.plate].index) for t in truth]
    on_plate = per_foot(np.asarray(over.any(axis=2)), points.sides, np.logical_or)
    scored = [t for t in truth if t.foot is not None and not (t.cut_start and t.cut_end)]
    note = "" if scored else "no plate contact of one foot with an onset or offset in the take"
    return PlateTrial(label, len(active), points, tuple(truth), on_plate, note)


def plate_trials(corpus_dir: Path) -> list[PlateTrial]:
    """Every C3D file under ``corpus_dir/c3d`` with at least one active force plate.

    Files that cannot be read are left out (the reader's own bench covers them).
    """
    trials = []
    files = sorted(p for p in (corpus_dir / "c3d").rglob("*") if p.suffix.lower() == ".c3d")
    for path in files:
        try:
            trial = plate_trial(path, str(path.relative_to(corpus_dir)))
        except InputError:
            continue
        if trial is not None:
            trials.append(trial)
    return trials


def score_plate_trial(trial: PlateTrial, params: FeetParams) -> PlateScore | None:
    """The detector's contacts against the trial's plates (None when it cannot be scored)."""
    if trial.points is None or trial.on_plate is None or trial.note:
        return None
    report = check_feet(trial.points, params)
    return score_contacts(trial.truth, report.contacts, trial.on_plate, trial.points.fps)


def _pooled(scores: Sequence[PlateScore]) -> tuple[float, float]:
    """F1 over pooled counts, and the mean |onset| and |offset| error pooled (ms)."""
    found = sum(s.found for s in scores)
    truth = sum(s.plate_contacts for s in scores)
    right = sum(s.right for s in scores)
    judged = sum(s.judged for s in scores)
    recall = found / truth if truth else 0.0
    precision = right / judged if judged else 0.0
    f1 = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
    errors = np.abs(np.concatenate([e for s in scores for e in (s.onset_ms, s.offset_ms)]))
    return f1, float(np.mean(errors)) if errors.size else float("inf")


@dataclass(frozen=True, slots=True)
class PlateRow:
    """One trial of the plate bench.

    Parameters
    ----------
    trial : PlateTrial
    params : FeetParams
        The parameters it was scored with (chosen on the other trials).
    score : PlateScore or None
    """

    trial: PlateTrial
    params: FeetParams
    score: PlateScore | None


def marker_params_by_leave_one_out(
    trials: Sequence[PlateTrial], grid: Sequence[dict[str, Any]] = MARKER_GRID
) -> tuple[list[PlateRow], FeetParams]:
    """Score each scorable trial with the contact parameters chosen on the others.

    The choice maximises the F1 of the pooled counts, then minimises the mean absolute onset
    and offset error pooled over the trials; ties go to the earlier grid entry (the defaults
    first).

    Returns
    -------
    rows : list of PlateRow
        One per trial, in order (unscorable trials with the defaults and no score).
    chosen : FeetParams
        The choice on all scorable trials.
    """
    scorable = [t for t in trials if not t.note and t.points is not None]
    candidates = [FeetParams(**values) for values in grid]
    table = [[score_plate_trial(t, p) for t in scorable] for p in candidates]

    def choose(keep: list[int]) -> int:
        keys = []
        for row in table:
            f1, timing = _pooled([s for k, s in enumerate(row) if k in keep and s is not None])
            keys.append((-f1, timing))
        return min(range(len(keys)), key=lambda i: keys[i])

    rows = []
    for trial in trials:
        if trial in scorable:
            k = scorable.index(trial)
            pick = choose([j for j in range(len(scorable)) if j != k])
            rows.append(PlateRow(trial, candidates[pick], table[pick][k]))
        else:
            rows.append(PlateRow(trial, FeetParams(), None))
    return rows, candidates[choose(list(range(len(scorable))))]
