"""``mocapqa bench feet``: injected slides and penetrations on real takes, false skate flags
on clean ones, threshold choice on a fit split, and speed.

Corpus and split: every BVH take of the corpus (:func:`mocapqa.bench.limits.corpus_files`),
split by the fixed rule of the limits bench (:func:`mocapqa.bench.limits.held_back_names`:
per rig, every take at sorted position ``i % 4 == 1`` is held back), with the iClone take
``005_05.bvh`` (real knee twist errors) moved to the held-back side so that it takes no part
in choosing a parameter. Bandai and Character Creator takes are in centimetres, as is
``bvh_test2.bvh`` (the corpus README); the other takes store no unit, and their centimetres
are read from the body height estimated from the leg length, taken as 170 cm.

Trials: on each take, each foot contact the clean take has (longer than 0.15 s) is given, one at
a time, a slide of 1, 2, 3, 5 and 8 cm in a seeded random horizontal direction, ramping over
the contact (:func:`mocapqa.feet.inject.inject_slide`), and separately a penetration of 1, 2,
3 and 5 cm over the middle half of the contact (:func:`mocapqa.feet.inject.inject_penetration`);
the whole check runs again on the changed take. A slide is found when a skate finding of that
foot overlaps the contact; a penetration when a penetration finding does. False flags are the
skate findings of the clean takes, per minute.

Choice: each ``(plant_height, plant_speed)`` pair of a small grid runs on the fit takes with
every contact's travel recorded; the skate threshold is then the smallest of a grid whose false
flags on the fit takes stay at or under :data:`MAX_FLAGS_PER_MINUTE`, and the pair with the best
recall of slides of 2 cm and more wins. The figures reported are those of the held-back takes
under the chosen parameters.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.bench.limits import corpus_files, held_back_names, split_group
from mocapqa.core.arrays import BoolArray
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.feet.check import check_feet
from mocapqa.feet.findings import Finding
from mocapqa.feet.fix import foot_rig, lock_feet, shift_ankles
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.ik import leg_subtree
from mocapqa.feet.inject import inject_penetration, inject_slide, leg_slide_offsets
from mocapqa.feet.lock import BLEND_S, Lock
from mocapqa.feet.markers import marker_foot_points
from mocapqa.feet.params import FeetParams
from mocapqa.feet.plates import (
    PlateContact,
    PlateScore,
    over_plates,
    plate_contacts,
    score_contacts,
)
from mocapqa.feet.points import SIDES, FootPoints, per_foot
from mocapqa.feet.tracks import horizontal_axes
from mocapqa.io.bvh import read_bvh
from mocapqa.io.c3d import read_c3d
from mocapqa.io.c3d_plates import read_force_plates
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import geodesic_angle
from mocapqa.limits.rig import rig_family
from mocapqa.pipeline.feet import motion_foot_points

__all__ = [
    "ASSUMED_HEIGHT_CM",
    "CLEANUP_SLIDES_CM",
    "CLEAN_FAMILIES",
    "DEPTHS_CM",
    "MARKER_GRID",
    "MAX_FLAGS_PER_MINUTE",
    "PLATE_HEIGHT",
    "PLATE_SPEED",
    "SLIDES_CM",
    "BenchTake",
    "Choice",
    "CleanupTrial",
    "FamilyFigures",
    "PlateRow",
    "PlateTrial",
    "Trial",
    "bench_takes",
    "choose_params",
    "clean_flags",
    "cleanup_trials",
    "family_figures",
    "feet_speed",
    "held_back_cleanup",
    "marker_params_by_leave_one_out",
    "plate_trial",
    "plate_trials",
    "run_trials",
    "score_plate_trial",
]

SLIDES_CM = (1.0, 2.0, 3.0, 5.0, 8.0)
"""Slides injected into every contact, centimetres."""
DEPTHS_CM = (1.0, 2.0, 3.0, 5.0)
"""Penetrations injected into every contact, centimetres."""
ASSUMED_HEIGHT_CM = 170.0
"""Body height read into takes without a unit, centimetres."""
MAX_FLAGS_PER_MINUTE = 1.0
"""False skate flags per minute allowed on the clean fit takes when choosing the threshold."""
CLEAN_FAMILIES = ("bandai",)
"""Rig families whose takes count as clean professional captures: Bandai Namco's dataset
(studio capture published for motion research). The Character Creator takes are retargets
of CMU captures and slide by 1–3 cm on planted feet in places (``007_04``: both points of the
planted foot move 1.4 cm together at 5 cm/s), the PyMO walk's right foot drifts on every step,
and the pybvh fixtures have no stated source, so their flags are reported, not counted as
false. The CMU walk is a studio capture too; it is held back by the split."""
LONG_TAKE_FRAMES = 100_000
"""Frames of the long take :func:`feet_speed` times (about 14 minutes at 120 fps)."""
HELD_BACK_ALWAYS = frozenset({"005_05.bvh"})
"""Takes kept out of every parameter choice whatever the split says."""
_CM_FAMILIES = frozenset({"bandai", "character_creator"})
_CM_TAKES = frozenset({"bvh_test2.bvh"})
_MIN_CONTACT_S = 0.15
_MAX_SINK_S = 0.5
_ON_FLOOR_CM = 0.5
_PLANT_GRID = (
    (0.006, 0.1), (0.006, 0.15), (0.01, 0.1), (0.01, 0.15), (0.01, 0.2), (0.015, 0.15),
)  # fmt: skip
_TRAVEL_GRID = tuple(np.round(np.arange(0.010, 0.0605, 0.002), 3))


@dataclass(frozen=True, slots=True)
class BenchTake:
    """A corpus take ready for the feet bench.

    Parameters
    ----------
    name : str
        File name.
    family : str
        Rig family (:func:`mocapqa.limits.rig.rig_family`).
    held_back : bool
        Whether the split keeps it out of parameter choice.
    points : FootPoints
    cm_per_unit : float
        Centimetres per take unit (read from the body height when ``unit_known`` is False).
    unit_known : bool
    """

    name: str
    family: str
    held_back: bool
    points: FootPoints
    cm_per_unit: float
    unit_known: bool

    @property
    def minutes(self) -> float:
        """Duration, minutes."""
        return self.points.n_frames / self.points.fps / 60.0


@dataclass(frozen=True, slots=True)
class Trial:
    """One injected error and what the check found.

    Parameters
    ----------
    take, foot : str
    start, end : int
        The contact's frames.
    kind : {"slide", "penetration"}
    size_cm : float
        Injected size.
    found : bool
    measured_cm : float
        Size of the overlapping finding (0 when none).
    """

    take: str
    foot: str
    start: int
    end: int
    kind: str
    size_cm: float
    found: bool
    measured_cm: float


def bench_takes(corpus_dir: Path) -> list[BenchTake]:
    """Every BVH take of the corpus with its foot points, split and scale.

    Takes whose rig has no legs the check can use are left out.
    """
    read = []
    for path in corpus_files(corpus_dir):
        family_probe = read_bvh(path)
        family = rig_family(family_probe.skeleton)
        known = family in _CM_FAMILIES or path.name in _CM_TAKES
        motion = read_bvh(path, length_unit="cm") if known else family_probe
        read.append((path.name, family, known, motion))
    held = held_back_names([(name, split_group(m.skeleton)) for name, _, _, m in read])
    takes = []
    for name, family, known, motion in read:
        try:
            points, _ = motion_foot_points(motion)
        except InputError:
            continue
        scale = 1.0 if known else ASSUMED_HEIGHT_CM / points.body_height
        takes.append(
            BenchTake(name, family, name in held or name in HELD_BACK_ALWAYS, points, scale, known)
        )
    return takes


def _overlapping(findings: Sequence[Finding], kind: str, foot: str, start: int, end: int) -> float:
    """Largest size of the findings of ``kind`` on ``foot`` overlapping ``start..end``."""
    sizes = [
        f.size
        for f in findings
        if f.kind == kind and f.foot == foot and f.start <= end and f.end >= start
    ]
    return max(sizes, default=0.0)


def clean_flags(take: BenchTake, params: FeetParams) -> tuple[list[float], int]:
    """Skate sizes (cm) the check reports on the clean take, and its number of contacts."""
    report = check_feet(take.points, params)
    sizes = [f.size * take.cm_per_unit for f in report.findings if f.kind == "skate"]
    return sizes, len(report.contacts)


def run_trials(
    take: BenchTake,
    params: FeetParams,
    seed: int,
    slides_cm: Sequence[float] = SLIDES_CM,
    depths_cm: Sequence[float] = DEPTHS_CM,
) -> list[Trial]:
    """Inject every slide and penetration into every contact of the clean take, one at a
    time, and check again (see the module notes)."""
    points = take.points
    clean = check_feet(points, params)
    rng = np.random.default_rng([seed, sum(take.name.encode())])
    trials = []
    for contact in clean.contacts:
        if (contact.end - contact.start + 1) / points.fps < _MIN_CONTACT_S:
            continue
        foot = points.side_indices(contact.foot)
        # Over the whole contact, or its middle second when it is longer.
        middle = (contact.start + contact.end) // 2
        reach = min((contact.end - contact.start) // 2, int(params.skate_window_s * points.fps / 2))
        slide_start, slide_end = middle - reach, middle + reach
        for size in slides_cm:
            angle = rng.uniform(0.0, 2.0 * np.pi)
            amount = size / take.cm_per_unit
            moved = inject_slide(
                points.positions, foot, slide_start, slide_end,
                (amount * np.cos(angle), amount * np.sin(angle)), clean.up,
            )  # fmt: skip
            report = check_feet(dataclasses.replace(points, positions=moved), params, clean.up)
            measured = _overlapping(report.findings, "skate", contact.foot, contact.start,
                                    contact.end) * take.cm_per_unit  # fmt: skip
            found = measured >= params.skate_travel * points.leg_length * take.cm_per_unit
            trials.append(Trial(take.name, contact.foot, contact.start, contact.end, "slide",
                                size, bool(found and measured > 0), measured))  # fmt: skip
        # The middle half of the contact, at most _MAX_SINK_S long.
        middle = (contact.start + contact.end) // 2
        half = min((contact.end - contact.start) // 4, int(_MAX_SINK_S * points.fps / 2))
        sink_start, sink_end = middle - half, middle + half
        # Only where the foot stands on the floor: lowering a foot that stands on a step
        # (or a contact the take floats through) is no penetration.
        lowest = np.min(clean.elevations[sink_start : sink_end + 1, foot], axis=1)
        if depths_cm and np.median(lowest) * take.cm_per_unit > _ON_FLOOR_CM:
            continue
        for depth in depths_cm:
            sunk = inject_penetration(
                points.positions, foot, sink_start, sink_end, depth / take.cm_per_unit, clean.up
            )
            report = check_feet(dataclasses.replace(points, positions=sunk), params, clean.up)
            measured = _overlapping(report.findings, "penetration", contact.foot, sink_start,
                                    sink_end)  # fmt: skip
            trials.append(Trial(take.name, contact.foot, contact.start, contact.end,
                                "penetration", depth, measured > 0,
                                measured * take.cm_per_unit))  # fmt: skip
    return trials


@dataclass(frozen=True, slots=True)
class Choice:
    """The parameters chosen on the fit takes, and their figures there.

    Parameters
    ----------
    params : FeetParams
    fit_takes : tuple of str
        The takes the choice was made on.
    fit_recall : float
        Share of fit slides of 2 cm and more found.
    fit_flags_per_minute : float
        Skate findings per minute on the clean fit takes.
    candidates : tuple of (float, float, float, float, float)
        Per grid pair: plant_height, plant_speed, the threshold chosen, fit recall ≥ 2 cm
        and fit flags per minute.
    """

    params: FeetParams
    fit_takes: tuple[str, ...]
    fit_recall: float
    fit_flags_per_minute: float
    candidates: tuple[tuple[float, float, float, float, float], ...]


def choose_params(
    takes: Sequence[BenchTake],
    seed: int,
    base: FeetParams | None = None,
    clean_families: tuple[str, ...] = CLEAN_FAMILIES,
) -> Choice:
    """Choose ``plant_height``, ``plant_speed`` and ``skate_travel`` on the fit takes (see the
    module notes): false flags are counted on the fit takes of ``clean_families``, recall on
    every fit take."""
    base = base or FeetParams()
    fit = [t for t in takes if not t.held_back]
    clean_takes = [t for t in fit if t.family in clean_families]
    minutes = sum(t.minutes for t in clean_takes)
    candidates = []
    best: tuple[float, float, FeetParams] | None = None
    for plant_height, plant_speed in _PLANT_GRID:
        probe = dataclasses.replace(
            base, plant_height=plant_height, plant_speed=plant_speed, skate_travel=0.0
        )
        # Sizes in leg lengths: the threshold is one.
        clean = np.array([s / (t.cm_per_unit * t.points.leg_length)
                          for t in clean_takes for s in clean_flags(t, probe)[0]])  # fmt: skip
        slides = [
            (trial.size_cm, trial.measured_cm / (t.cm_per_unit * t.points.leg_length))
            for t in fit
            for trial in run_trials(t, probe, seed, depths_cm=())
        ]
        sizes = np.array([s for s, _ in slides])
        measured = np.array([m for _, m in slides])
        for travel in _TRAVEL_GRID:
            flags = float(np.sum(clean >= travel)) / minutes
            if flags <= MAX_FLAGS_PER_MINUTE:
                big = sizes >= 2.0
                recall = float(np.mean(measured[big] >= travel)) if big.any() else 0.0
                candidates.append((plant_height, plant_speed, float(travel), recall, flags))
                if best is None or (recall, -flags) > (best[0], -best[1]):
                    chosen = dataclasses.replace(
                        base, plant_height=plant_height, plant_speed=plant_speed,
                        skate_travel=float(travel),
                    )  # fmt: skip
                    best = (recall, flags, chosen)
                break
    if best is None:
        raise InputError(
            f"Expected a skate threshold under {_TRAVEL_GRID[-1]} leg lengths with at most "
            f"{MAX_FLAGS_PER_MINUTE} false flags per minute on the fit takes, got none"
        )
    return Choice(best[2], tuple(t.name for t in fit), best[0], best[1], tuple(candidates))


@dataclass(frozen=True, slots=True)
class FamilyFigures:
    """Figures of one rig family's held-back (or fit) takes.

    Parameters
    ----------
    family : str
    split : {"fit", "held back"}
    takes, minutes, contacts : int, float, int
    skate_per_minute : float
        Skate findings per minute on the clean takes.
    slide_recall : dict of float to (int, int)
        Injected slide size (cm) → (found, tried).
    penetration_recall : dict of float to (int, int)
        Injected depth (cm) → (found, tried).
    slide_error_cm : float
        Median |measured − injected| of the slides found, centimetres.
    """

    family: str
    split: str
    takes: int
    minutes: float
    contacts: int
    skate_per_minute: float
    slide_recall: dict[float, tuple[int, int]]
    penetration_recall: dict[float, tuple[int, int]]
    slide_error_cm: float


def _recall(
    trials: Sequence[Trial], kind: str, sizes: Sequence[float]
) -> dict[float, tuple[int, int]]:
    """Injected size → (found, tried) for the trials of ``kind``."""
    return {
        size: (
            sum(t.found for t in trials if t.kind == kind and t.size_cm == size),
            sum(1 for t in trials if t.kind == kind and t.size_cm == size),
        )
        for size in sizes
    }


def family_figures(
    takes: Sequence[BenchTake], params: FeetParams, seed: int
) -> list[FamilyFigures]:
    """Per rig family and split: false skate flags on the clean takes and injected recall."""
    rows = []
    for split in ("fit", "held back"):
        for family in sorted({t.family for t in takes}):
            group = [t for t in takes if t.family == family and t.held_back == (split != "fit")]
            if not group:
                continue
            flags, contacts = 0, 0
            trials: list[Trial] = []
            for take in group:
                sizes, count = clean_flags(take, params)
                flags += len(sizes)
                contacts += count
                trials += run_trials(take, params, seed)
            minutes = sum(t.minutes for t in group)
            slides = _recall(trials, "slide", SLIDES_CM)
            sinks = _recall(trials, "penetration", DEPTHS_CM)
            errors = [abs(t.measured_cm - t.size_cm) for t in trials
                      if t.kind == "slide" and t.found]  # fmt: skip
            rows.append(
                FamilyFigures(
                    family, split, len(group), minutes, contacts, flags / minutes,
                    slides, sinks,
                    float(np.median(errors)) if errors else float("nan"),
                )
            )  # fmt: skip
    return rows


def feet_speed(
    takes: Sequence[BenchTake], params: FeetParams, repeats: int = 3, concatenate: bool = False
) -> float:
    """Foot-frames (frames × 2 feet) checked per CPU second, best of ``repeats`` passes
    (:func:`time.process_time`): over the takes one by one, or with ``concatenate`` over one
    long take made of all of them end to end, repeated to at least :data:`LONG_TAKE_FRAMES`
    frames (the per-take overhead, about 2 ms, then counts once)."""
    if concatenate:
        parts = [t.points for t in takes]
        copies = max(1, -(-LONG_TAKE_FRAMES // sum(p.n_frames for p in parts)))
        joined = dataclasses.replace(
            parts[0],
            positions=np.concatenate([p.positions for p in parts] * copies),
            pelvis=np.concatenate(
                [p.pelvis if p.pelvis is not None else np.full((p.n_frames, 3), np.nan)
                 for p in parts] * copies
            ),
        )  # fmt: skip
        return feet_speed([dataclasses.replace(takes[0], points=joined)], params, repeats)
    frames = sum(t.points.n_frames for t in takes) * 2
    best = float("inf")
    for _ in range(repeats):
        start = time.process_time()
        for take in takes:
            check_feet(take.points, params)
        best = min(best, time.process_time() - start)
    return frames / best if best > 0 else float("inf")


# Force plates ---------------------------------------------------------------------------------

PLATE_HEIGHT = 0.1
"""A foot point stands on a plate within this distance of its plane, leg lengths (9 cm)."""
PLATE_SPEED = 1.0
"""... and slower than this, leg lengths per second (a swing foot crossing a plate low moves
at several)."""
MARKER_GRID: tuple[dict[str, float], ...] = tuple(
    {
        "contact_speed": cs,
        "release_speed": rs,
        "contact_height": ch,
        "release_height": rh,
        "speed_window_s": w,
    }
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
    trials: Sequence[PlateTrial], grid: Sequence[dict[str, float]] = MARKER_GRID
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


# Foot cleanup ---------------------------------------------------------------------------------

CLEANUP_SLIDES_CM = (2.0, 5.0, 8.0)
"""Slides injected into the legs of the held-back takes before the foot lock, centimetres."""


@dataclass(frozen=True, slots=True)
class CleanupTrial:
    """One slide injected through a leg, then ``feet fix --apply all``.

    Parameters
    ----------
    take, family, foot : str
    size_cm : float
        Injected slide.
    clean_cm, injected_cm, fixed_cm : float
        The check's travel of the contact (skate measure with no threshold) on the clean
        take, the injected one and the fixed one, centimetres.
    hip_knee_deg_blends : float
        Largest change of a hip or knee local rotation in the blend frames (outside the
        locked contacts), degrees.
    hip_knee_deg_outside : float
        The same outside the locked contacts and their blends (0 by construction).
    upper_body_changed : int
        Joints outside the legs whose world position changed in any frame.
    pop_cm_s : dict of str to float
        Per anchor ("middle", "start"), the largest speed the lock adds to an ankle in a
        blend frame, cm/s.
    clamped_frames, locked_frames : int
        Solved foot-frames out of the leg's reach, and all solved foot-frames.
    cpu_s : float
        CPU seconds of the lock (forward kinematics, IK, the travel after).
    """

    take: str
    family: str
    foot: str
    size_cm: float
    clean_cm: float
    injected_cm: float
    fixed_cm: float
    hip_knee_deg_blends: float
    hip_knee_deg_outside: float
    upper_body_changed: int
    pop_cm_s: dict[str, float]
    clamped_frames: int
    locked_frames: int
    cpu_s: float


def _travel_cm(
    motion: Motion, up: UpAxis, params: FeetParams, foot: str, start: int, end: int, scale: float
) -> float:
    """The check's travel (skate with no threshold) of ``foot`` over motion frames
    ``start..end``, centimetres."""
    points, skipped = motion_foot_points(motion)
    report = check_feet(points, dataclasses.replace(params, skate_travel=0.0), up)
    return _overlapping(report.findings, "skate", foot, start - skipped, end - skipped) * scale


def cleanup_trials(
    path: Path,
    family: str,
    params: FeetParams,
    seed: int,
    slides_cm: Sequence[float] = CLEANUP_SLIDES_CM,
) -> list[CleanupTrial]:
    """Inject each slide into each contact (longer than 0.15 s) of a clean take through the
    leg (:func:`mocapqa.feet.inject.leg_slide_offsets`, over the contact's middle as
    :func:`run_trials` does, held to the contact's end and eased out after it), run the check
    on the result and lock every contact it finds (``--apply all``); measure what is left
    of the slide and what else changed (:class:`CleanupTrial`)."""
    known = family in _CM_FAMILIES or path.name in _CM_TAKES
    motion = read_bvh(path, length_unit="cm") if known else read_bvh(path)
    points, skipped = motion_foot_points(motion)
    scale = 1.0 if known else ASSUMED_HEIGHT_CM / points.body_height
    clean = check_feet(points, params)
    rig = foot_rig(motion)
    legs = leg_subtree(motion.skeleton, rig.legs[0].hip) | leg_subtree(
        motion.skeleton, rig.legs[1].hip
    )
    hip_knee = [j for leg in rig.legs for j in (leg.hip, leg.knee)]
    blend = max(1, round(BLEND_S * motion.fps))
    flat_axes = list(horizontal_axes(clean.up.axis))
    plant = params.plant_speed * points.leg_length
    rng = np.random.default_rng([seed, sum(path.name.encode())])
    trials = []
    for contact in clean.contacts:
        if (contact.end - contact.start + 1) / points.fps < _MIN_CONTACT_S:
            continue
        start, end = contact.start + skipped, contact.end + skipped
        foot = SIDES.index(contact.foot)
        middle = (start + end) // 2
        reach = min((end - start) // 2, int(params.skate_window_s * points.fps / 2))
        clean_cm = _travel_cm(motion, clean.up, params, contact.foot, start, end, scale)
        for size in slides_cm:
            angle = rng.uniform(0.0, 2.0 * np.pi)
            displacement = np.zeros(3)
            displacement[flat_axes] = (size / scale) * np.array([np.cos(angle), np.sin(angle)])
            offsets, changed = leg_slide_offsets(
                motion.n_frames, foot, middle - reach, middle + reach, end, displacement, blend
            )
            injected, _ = shift_ankles(motion, rig, offsets, changed)
            in_points, _ = motion_foot_points(injected)
            report = check_feet(in_points, params, clean.up)
            locks = [Lock(c.foot, c.start + skipped, c.end + skipped) for c in report.contacts]
            pops = {}
            for anchor in ("start", "middle"):
                began = time.process_time()
                result = lock_feet(
                    injected,
                    rig,
                    clean.up,
                    locks,
                    plant,
                    points.leg_length,
                    anchor,
                    first=skipped,
                )
                cpu = time.process_time() - began
                before = forward_kinematics(injected)[1]
                after = forward_kinematics(result.motion)[1]
                moved = (
                    after[:, [leg.ankle for leg in rig.legs]]
                    - before[:, [leg.ankle for leg in rig.legs]]
                )
                added = np.linalg.norm(np.diff(moved, axis=0), axis=-1) * motion.fps * scale
                pops[anchor] = float(added.max()) if added.size else 0.0
            inside = np.zeros((motion.n_frames, 2), dtype=bool)
            for lock in locks:
                inside[lock.start : lock.end + 1, SIDES.index(lock.foot)] = True
            angles = np.rad2deg(
                geodesic_angle(injected.quats[:, hip_knee], result.motion.quats[:, hip_knee])
            ).reshape(motion.n_frames, 2, 2)  # (F, leg, hip/knee)
            per_leg = angles.max(axis=-1)
            blends = result.changed & ~inside
            untouched = ~result.changed & ~inside
            trials.append(
                CleanupTrial(
                    path.name, family, contact.foot, size, clean_cm,
                    _travel_cm(injected, clean.up, params, contact.foot, start, end, scale),
                    _travel_cm(result.motion, clean.up, params, contact.foot, start, end, scale),
                    float(per_leg[blends].max(initial=0.0)),
                    float(per_leg[untouched].max(initial=0.0)),
                    int(np.sum(np.any(after[:, ~legs] != before[:, ~legs], axis=(0, 2)))),
                    pops, int(result.clamped.sum()), int(result.changed.sum()), cpu,
                )
            )  # fmt: skip
    return trials


def held_back_cleanup(
    corpus_dir: Path, takes: Sequence[BenchTake], params: FeetParams, seed: int
) -> list[CleanupTrial]:
    """:func:`cleanup_trials` on every held-back take of ``takes`` (the bench's split)."""
    held = {t.name: t.family for t in takes if t.held_back}
    trials: list[CleanupTrial] = []
    for path in corpus_files(corpus_dir):
        if path.name in held:
            trials += cleanup_trials(path, held[path.name], params, seed)
    return trials
