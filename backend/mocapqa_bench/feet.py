"""``mocapqa bench feet``: injected slides and penetrations on real takes, false skate flags
on clean ones, threshold choice on a fit split, and speed.

Corpus and split: every BVH take of the corpus (:func:`mocapqa_bench.limits.corpus_files`),
split by the fixed rule of the limits bench (:func:`mocapqa_bench.limits.held_back_names`:
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

Choice: each ``(plant_height, plant_speed, sole_depth, slide_height)`` of a small grid runs on
the fit takes with every contact's travel recorded; the skate threshold is then the smallest of
a grid whose false flags on the fit takes stay at or under :data:`MAX_FLAGS_PER_MINUTE`, and
the entry with the best recall of slides of 2 cm and more wins (fewer flags on a tie). The
figures reported are those of the held-back takes under the chosen parameters.

The contact detector against force plates is :mod:`mocapqa_bench.feet_plates`; the foot lock
on slides injected through the leg is :mod:`mocapqa_bench.feet_cleanup`.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.errors import InputError
from mocapqa.feet.check import check_feet
from mocapqa.feet.findings import Finding
from mocapqa.feet.inject import inject_penetration, inject_slide
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import FootPoints
from mocapqa.io.bvh import read_bvh
from mocapqa.limits.rig import rig_family
from mocapqa.pipeline.feet import motion_foot_points
from mocapqa_bench.limits import corpus_files, held_back_names, split_group

__all__ = [
    "ASSUMED_HEIGHT_CM",
    "CLEAN_FAMILIES",
    "CM_FAMILIES",
    "CM_TAKES",
    "DEPTHS_CM",
    "HELD_BACK_ALWAYS",
    "MAX_FLAGS_PER_MINUTE",
    "MIN_CONTACT_S",
    "SLIDES_CM",
    "BenchTake",
    "Choice",
    "FamilyFigures",
    "Trial",
    "bench_takes",
    "choose_params",
    "clean_flags",
    "family_figures",
    "feet_speed",
    "overlapping_size",
    "run_trials",
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
CM_FAMILIES = frozenset({"bandai", "character_creator"})
"""Rig families whose takes are in centimetres."""
CM_TAKES = frozenset({"bvh_test2.bvh"})
"""Takes of other families in centimetres (the corpus README)."""
MIN_CONTACT_S = 0.15
"""Shortest contact given an injected error, seconds."""
_MAX_SINK_S = 0.5
_ON_FLOOR_CM = 0.5
_PLANT_GRID = ((0.006, 0.1), (0.01, 0.15))
"""(plant_height, plant_speed) pairs tried."""
_SOLE_GRID = (0.0, 0.03, 0.045, 0.06, 0.075)
"""sole_depth values tried, leg lengths."""
_SLIDE_GRID = (0.0, 0.02)
"""slide_height values tried, leg lengths (slide_speed keeps its default)."""
_TRAVEL_GRID = tuple(np.round(np.arange(0.010, 0.0605, 0.001), 3))


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
        known = family in CM_FAMILIES or path.name in CM_TAKES
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


def overlapping_size(
    findings: Sequence[Finding], kind: str, foot: str, start: int, end: int
) -> float:
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
        if (contact.end - contact.start + 1) / points.fps < MIN_CONTACT_S:
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
            measured = overlapping_size(report.findings, "skate", contact.foot, contact.start,
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
            measured = overlapping_size(report.findings, "penetration", contact.foot, sink_start,
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
    candidates : tuple of (float, float, float, float, float, float, float)
        Per grid entry: plant_height, plant_speed, sole_depth, slide_height, the threshold
        chosen, fit recall ≥ 2 cm and fit flags per minute.
    """

    params: FeetParams
    fit_takes: tuple[str, ...]
    fit_recall: float
    fit_flags_per_minute: float
    candidates: tuple[tuple[float, float, float, float, float, float, float], ...]


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
        for sole_depth in _SOLE_GRID:
            for slide_height in _SLIDE_GRID:
                probe = dataclasses.replace(
                    base, plant_height=plant_height, plant_speed=plant_speed,
                    sole_depth=sole_depth, slide_height=slide_height, skate_travel=0.0,
                )  # fmt: skip
                travel, recall, flags = _smallest_travel(fit, clean_takes, minutes, probe, seed)
                if travel is None:
                    continue
                candidates.append(
                    (plant_height, plant_speed, sole_depth, slide_height, travel, recall, flags)
                )
                if best is None or (recall, -flags) > (best[0], -best[1]):
                    best = (recall, flags, dataclasses.replace(probe, skate_travel=travel))
    if best is None:
        raise InputError(
            f"Expected a skate threshold under {_TRAVEL_GRID[-1]} leg lengths with at most "
            f"{MAX_FLAGS_PER_MINUTE} false flags per minute on the fit takes, got none"
        )
    return Choice(best[2], tuple(t.name for t in fit), best[0], best[1], tuple(candidates))


def _smallest_travel(
    fit: Sequence[BenchTake],
    clean_takes: Sequence[BenchTake],
    minutes: float,
    probe: FeetParams,
    seed: int,
) -> tuple[float | None, float, float]:
    """The smallest skate threshold of the grid with at most :data:`MAX_FLAGS_PER_MINUTE`
    false flags on the clean fit takes under ``probe`` (None when none qualifies), with its
    recall of fit slides of 2 cm and more and its flags per minute."""
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
    big = sizes >= 2.0
    for travel in _TRAVEL_GRID:
        flags = float(np.sum(clean >= travel)) / minutes
        if flags <= MAX_FLAGS_PER_MINUTE:
            recall = float(np.mean(measured[big] >= travel)) if big.any() else 0.0
            return float(travel), recall, flags
    return None, 0.0, 0.0


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
