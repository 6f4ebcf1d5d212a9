"""Gap-fill benchmark on real marker takes: RMSE per method and gap length.

Conventions
-----------
Gaps of 0.05–2 s (uniform within four length bins) are hidden in stretches where the target
marker is recorded, in takes as their systems wrote them (their own gaps included). Half of the
events hide the target alone; the other half are occlusions that also hide one or more other
markers of its segment over overlapping intervals (starts and ends moved by up to a quarter of
the gap). A marker's segment is the markers whose distance to it has a standard deviation of at
most ``SEGMENT_STD_MM`` over the take; only events where at least three of them stay visible
over the target's gap and the frame either side are drawn. Each event is filled by the cubic
spline (no length limit), the rigid fill, the PCA fill and the automatic choice of
:func:`~mocapqa.markers.fill.plan_gap` (one method or their blend); the RMSE is the root mean
square 3-D error in mm over every hidden sample of the targets of a bin (pooled). Events are
seeded per file and seed.
"""

from __future__ import annotations

import zlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError
from mocapqa.io.c3d import read_c3d
from mocapqa.markers.fill import FillContext, FillParams, plan_gap
from mocapqa.markers.fill_methods import spline_fill
from mocapqa.markers.fill_params import CHOICES
from mocapqa.markers.params import unit_scale

__all__ = [
    "BENCH_FILES",
    "BINS_S",
    "FILL_CANDIDATES",
    "SEGMENT_STD_MM",
    "FillEvent",
    "fill_errors",
    "fill_table",
    "load_points",
    "summarise",
    "tune_leave_one_out",
]

BENCH_FILES = (
    "c3d/cmu/cmu_02_05.c3d",
    "c3d/optitrack/kinematics_tennis_serve.c3d",
    "c3d/vicon/nick_freeform_001.c3d",
    "c3d/btk/Eb015pr.c3d",
    "c3d/cmu/cmu_dribble_shoot_basketball.c3d",
)
"""Takes of the benchmark, relative to the corpus folder."""

BINS_S = ((0.05, 0.2), (0.2, 0.5), (0.5, 1.0), (1.0, 2.0))
"""Gap length bins (seconds, lower bound inclusive)."""

SEGMENT_STD_MM = 10.0
"""Largest standard deviation (mm) of the distance between two markers of one segment."""

METHOD_COLUMNS = ("spline", "rigid", "pca", "relative", "auto")

FILL_CANDIDATES = tuple(
    FillParams(cv_match=match, blend_power=power)
    for match in ("spread", "motion")
    for power in (0.0, 2.0, 3.0)
)
"""The settings :func:`tune_leave_one_out` chooses from for the benchmark's held-out table:
where the cross-validation's other trials go (spread over the take, or where the take moves
as over the gap) and the blend's power (0: no blend)."""


def load_points(path: Path) -> tuple[FloatArray, float, float]:
    """Marker positions of a C3D file (:func:`mocapqa.io.c3d.read_c3d`).

    Parameters
    ----------
    path : Path
        The C3D file.

    Returns
    -------
    positions : ndarray, shape (F, M, 3)
        Positions in the file's unit, NaN where missing.
    fps : float
        Point rate (Hz).
    units_per_mm : float
        File units per mm.

    Raises
    ------
    InputError
        If the point unit is not mm, cm or m.
    """
    points = read_c3d(path).points
    if points.length_unit not in ("mm", "cm", "m"):
        raise InputError(
            f"{path}: Expected a point unit of mm, cm or m, got {points.length_unit!r}"
        )
    return points.positions, points.fps, unit_scale(points.length_unit)


@dataclass(frozen=True, slots=True)
class FillEvent:
    """One injected gap's squared errors (mm²) summed over its samples, per method.

    Parameters
    ----------
    file : str
        The take, relative to the corpus folder.
    bin : int
        Index into ``BINS_S``.
    frames : int
        Hidden samples of the target.
    occlusion : bool
        Other markers of the segment were hidden too.
    sq_error : dict of str to float
        Summed squared 3-D error per method (NaN where the method did not fill).
    chosen : str
        The method the automatic choice took (empty when none).
    """

    file: str
    bin: int
    frames: int
    occlusion: bool
    sq_error: dict[str, float]
    chosen: str


def _segment_std(positions: FloatArray, visible: BoolArray, m: int) -> FloatArray:
    """Standard deviation of each marker's distance to marker ``m``, shape (M,)."""
    d = np.linalg.norm(positions - positions[:, m][:, None], axis=2)
    ok = visible & visible[:, m][:, None]
    count = ok.sum(axis=0)
    d0 = np.where(ok, d, 0.0)
    mean = d0.sum(axis=0) / np.maximum(count, 1)
    var = np.where(ok, (d0 - mean) ** 2, 0.0).sum(axis=0) / np.maximum(count, 1)
    std = np.sqrt(var)
    std[(count < 10) | (np.arange(std.size) == m)] = np.inf
    return np.asarray(std)


def fill_errors(
    positions: FloatArray,
    fps: float,
    units_per_mm: float,
    rng: np.random.Generator,
    *,
    file: str = "",
    events_per_bin: int = 8,
    params: FillParams | None = None,
) -> list[FillEvent]:
    """Inject seeded gaps into one take and fill each by every method.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        The take in file units, NaN where missing.
    fps : float
        Frame rate (Hz).
    units_per_mm : float
        File units per mm.
    rng : numpy.random.Generator
        Source of the events.
    file : str
        Name recorded in the events.
    events_per_bin : int
        Events drawn per length bin (fewer when the take has no room for them).
    params : FillParams, optional
        Fill settings.

    Returns
    -------
    list of FillEvent
    """
    params = params or FillParams()
    visible: BoolArray = np.asarray(~np.isnan(positions).any(axis=2))
    n, markers = visible.shape
    seg_limit = SEGMENT_STD_MM * units_per_mm
    stds: dict[int, FloatArray] = {}
    events: list[FillEvent] = []
    for k, (low, high) in enumerate(BINS_S):
        drawn = 0
        for _ in range(events_per_bin * 40):
            if drawn == events_per_bin:
                break
            length = max(1, round(rng.uniform(low, high) * fps))
            m = int(rng.integers(markers))
            start = int(rng.integers(3, max(4, n - length - 3)))
            end = start + length - 1
            if end > n - 4 or not visible[start - 3 : end + 4, m].all():
                continue
            if m not in stds:
                stds[m] = _segment_std(positions, visible, m)
            segment = np.flatnonzero(stds[m] <= seg_limit)
            segment = segment[visible[start - 1 : end + 2][:, segment].all(axis=0)]
            if segment.size < 3:
                continue
            occlusion = bool(rng.random() < 0.5) and segment.size > 3
            hidden = positions.copy()
            hidden[start : end + 1, m] = np.nan
            if occlusion:
                count = int(rng.integers(1, segment.size - 2))
                quarter = max(1, length // 4)
                for j in rng.choice(segment, size=count, replace=False).tolist():
                    s = int(np.clip(start + rng.integers(-quarter, quarter + 1), 0, n - 1))
                    e = int(np.clip(end + rng.integers(-quarter, quarter + 1), s, n - 1))
                    hidden[s : e + 1, j] = np.nan
            hvis: BoolArray = np.asarray(~np.isnan(hidden).any(axis=2))
            if (hvis[start - 1 : end + 2][:, segment].all(axis=0)).sum() < 3:
                continue
            events.append(
                _fill_event(hidden, fps, units_per_mm, params, positions, m, start, end, file, k)
            )
            events[-1] = replace(events[-1], occlusion=occlusion)
            drawn += 1
    return events


def _fill_event(
    hidden: FloatArray,
    fps: float,
    units_per_mm: float,
    params: FillParams,
    truth: FloatArray,
    m: int,
    start: int,
    end: int,
    file: str,
    k: int,
) -> FillEvent:
    context = FillContext(hidden, fps, params, units_per_mm)
    plan = plan_gap(context, m, start, end)
    fills = dict(plan.fills)
    spline = spline_fill(
        hidden, context.visible, m, start, end,
        window=context.spline_window, max_length=hidden.shape[0],
    )  # fmt: skip
    if spline is None:
        fills.pop("spline", None)
    else:
        fills["spline"] = spline
    chosen, _ = plan.best()
    if chosen is not None:
        fills["auto"] = plan.fills[chosen]
    target = truth[start : end + 1, m]
    sq = {
        name: (
            float(np.sum((fills[name] - target) ** 2)) / units_per_mm**2
            if name in fills
            else float("nan")
        )
        for name in METHOD_COLUMNS
    }
    return FillEvent(file, k, end - start + 1, False, sq, chosen or "")


def summarise(events: Sequence[FillEvent]) -> list[dict[str, Any]]:
    """Pool events into one row per length bin.

    Parameters
    ----------
    events : sequence of FillEvent

    Returns
    -------
    list of dict
        Per bin: ``bin`` (label, s), ``gaps``, ``occlusions``, ``<method>_mm`` (pooled RMSE over
        the events every method filled), ``unfilled`` (events some method did not fill),
        ``auto_vs_spline`` and ``auto_vs_pca`` (RMSE ratios) and ``chosen`` (count per method).
    """
    rows: list[dict[str, Any]] = []
    for k, (low, high) in enumerate(BINS_S):
        mine = [e for e in events if e.bin == k]
        full = [e for e in mine if all(np.isfinite(e.sq_error[c]) for c in METHOD_COLUMNS)]
        frames = sum(e.frames for e in full)
        row: dict[str, Any] = {
            "bin": f"{low:g}-{high:g}",
            "gaps": len(full),
            "occlusions": sum(e.occlusion for e in full),
            "unfilled": len(mine) - len(full),
        }
        for c in METHOD_COLUMNS:
            total = sum(e.sq_error[c] for e in full)
            row[f"{c}_mm"] = float(np.sqrt(total / frames)) if frames else float("nan")
        row["auto_vs_spline"] = row["auto_mm"] / row["spline_mm"] if full else float("nan")
        row["auto_vs_pca"] = row["auto_mm"] / row["pca_mm"] if full else float("nan")
        row["chosen"] = {c: sum(e.chosen == c for e in full) for c in CHOICES}
        rows.append(row)
    return rows


def _events(
    corpus_dir: Path,
    seeds: Iterable[int],
    files: Sequence[str],
    events_per_bin: int,
    params: FillParams,
) -> list[FillEvent]:
    from threadpoolctl import threadpool_limits  # type: ignore[import-untyped]

    events: list[FillEvent] = []
    for name in files:
        positions, fps, units_per_mm = load_points(corpus_dir / name)
        for seed in seeds:
            with threadpool_limits(limits=1, user_api="blas"):
                rng = np.random.default_rng([seed, zlib.crc32(name.encode())])
                events += fill_errors(
                    positions, fps, units_per_mm, rng,
                    file=name, events_per_bin=events_per_bin, params=params,
                )  # fmt: skip
    return events


def fill_table(
    corpus_dir: Path,
    seeds: Iterable[int] = (0,),
    files: Sequence[str] = BENCH_FILES,
    *,
    events_per_bin: int = 8,
    params: FillParams | None = None,
) -> list[dict[str, Any]]:
    """The benchmark table: pooled fill RMSE (mm) per gap-length bin and method.

    Parameters
    ----------
    corpus_dir : Path
        The real-data corpus folder.
    seeds : iterable of int
        One set of events per seed and file.
    files : sequence of str
        Takes, relative to ``corpus_dir``.
    events_per_bin : int
        Events per bin, file and seed.
    params : FillParams, optional
        Fill settings.

    Returns
    -------
    list of dict
        One row per bin, as :func:`summarise`.
    """
    seeds = list(seeds)
    return summarise(_events(corpus_dir, seeds, files, events_per_bin, params or FillParams()))


def tune_leave_one_out(
    corpus_dir: Path,
    candidates: Sequence[FillParams],
    seeds: Iterable[int] = (0,),
    files: Sequence[str] = BENCH_FILES,
    *,
    events_per_bin: int = 8,
) -> tuple[list[dict[str, Any]], list[FillEvent]]:
    """Choose fill settings leaving each file out, and score them on the file left out.

    For each file, the candidate with the lowest pooled automatic-fill RMSE over the other files'
    events (all bins) is chosen, and that candidate's events on the left-out file are kept.

    Parameters
    ----------
    corpus_dir : Path
        The real-data corpus folder.
    candidates : sequence of FillParams
        The settings to choose from.
    seeds, files, events_per_bin
        As in :func:`fill_table`.

    Returns
    -------
    choices : list of dict
        Per file: ``file``, ``chosen`` (index into ``candidates``) and ``train_auto_mm`` (the
        other files' pooled automatic RMSE of every candidate).
    events : list of FillEvent
        The held-out events (pass them to :func:`summarise` for the table).
    """
    seeds = list(seeds)
    per = [_events(corpus_dir, seeds, files, events_per_bin, p) for p in candidates]
    choices: list[dict[str, Any]] = []
    held: list[FillEvent] = []
    for name in files:
        scores = []
        for events in per:
            train = [e for e in events if e.file != name and np.isfinite(e.sq_error["auto"])]
            frames = sum(e.frames for e in train)
            scores.append(float(np.sqrt(sum(e.sq_error["auto"] for e in train) / max(frames, 1))))
        best = int(np.argmin(scores))
        choices.append({"file": name, "chosen": best, "train_auto_mm": scores})
        held += [e for e in per[best] if e.file == name]
    return choices, held
