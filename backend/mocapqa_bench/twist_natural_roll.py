"""The natural roll figures of ``mocapqa bench twist``: the robust detector's event jumps on
clean takes (what each rig segment's natural roll level is read from), and injected level
shifts of small offsets, found and applied with and without the natural roll levels."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.io.bvh import read_bvh
from mocapqa.limits.rig import rig_family
from mocapqa.metrics.twist import (
    rotation_errors_deg,
)
from mocapqa.twist.analysis import analyze_twist, detect_chains
from mocapqa.twist.angles import chain_geometry
from mocapqa.twist.inject import inject_twist_errors
from mocapqa.twist.natural_roll import NaturalRoll, event_jumps_deg, natural_key
from mocapqa_bench.twist import RIGS, BenchFile, seeded_injections

__all__ = ["OFFSET_BANDS", "SmallOffsetRow", "clean_event_jumps", "small_offset_rows"]

OFFSET_BANDS = ((5.0, 10.0), (10.0, 15.0), (15.0, 20.0), (20.0, 180.0))
"""Bands of injected offset magnitude, degrees, of the small-offset table (the last is > 20°)."""


def clean_event_jumps(files: Sequence[BenchFile]) -> dict[str, FloatArray]:
    """Absolute jumps of the robust detector's events on the clean takes ``files``, degrees.

    Returns
    -------
    dict
        :func:`mocapqa.twist.natural_roll.natural_key` (rig family, segment) → jumps; keys with
        no event are absent.
    """
    out: dict[str, list[FloatArray]] = {}
    for bench_file in files:
        motion = read_bvh(bench_file.path)
        geometries = tuple(
            chain_geometry(motion.skeleton, c) for c in limb_chains(find_roles(motion.skeleton))
        )
        detection = detect_chains(motion.quats, geometries, motion.fps)
        family = rig_family(motion.skeleton)
        for segment, jumps in event_jumps_deg(detection, geometries).items():
            out.setdefault(natural_key(family, segment), []).append(jumps)
    return {k: np.concatenate(v) for k, v in out.items()}


@dataclass(frozen=True, slots=True)
class SmallOffsetRow:
    """Injected level shifts of one rig and offset band (:func:`small_offset_rows`).

    Parameters
    ----------
    rig : str
    band : tuple of float
        Offset magnitude band, degrees ``[low, high)``.
    injected : int
        Intervals injected.
    distinguishable : int
        Of them, those larger than the natural roll level of their rig segment.
    found : int
        Intervals that a reported interval of their joint overlaps.
    applied_before, applied : int
        Intervals that an interval applied by default overlaps, without and with the natural
        roll rule.
    hidden_applied_before, hidden_applied : int
        The same among the intervals that are not distinguishable.
    frames, corrected_before, corrected : int
        Injected frames and those corrected (at most 20 % of the rotation error left), without
        and with the natural roll rule.
    """

    rig: str
    band: tuple[float, float]
    injected: int
    distinguishable: int
    found: int
    applied_before: int
    applied: int
    hidden_applied_before: int
    hidden_applied: int
    frames: int
    corrected_before: int
    corrected: int


def small_offset_rows(
    files: Sequence[BenchFile],
    natural: NaturalRoll,
    seed: int = 0,
    repeats: int = 2,
) -> list[SmallOffsetRow]:
    """Injected level shifts by offset band and rig: found, applied by default and corrected,
    without and with the natural roll rule, and how many are larger than their rig segment's
    natural roll level.

    The injections are those of :func:`run_twist_bench` (``kind="level"``, same seeds), so the
    rows split its level-shift figures of the same takes.

    Parameters
    ----------
    files : sequence of BenchFile
        Takes to inject (the bench passes the held-out ones).
    natural : NaturalRoll
        The levels of the rule (and of "distinguishable").
    seed, repeats : int
        As in :func:`run_twist_bench`.

    Returns
    -------
    list of SmallOffsetRow
        Per rig of ``files`` (in :data:`RIGS` order) and band of :data:`OFFSET_BANDS`.
    """
    counts: dict[tuple[str, int], np.ndarray] = {}
    for bench_file in files:
        motion = read_bvh(bench_file.path)
        family = rig_family(motion.skeleton)
        injections = seeded_injections(motion, bench_file, seed, repeats, inject_twist_errors)
        for _, corrupted, truth in injections:
            analyses = [analyze_twist(corrupted, natural_roll=NaturalRoll()),
                        analyze_twist(corrupted, natural_roll=natural)]  # fmt: skip
            names = list(corrupted.skeleton.names)
            for injected in truth.intervals:
                size = abs(injected.offset_deg)
                band = next(
                    (k for k, (low, high) in enumerate(OFFSET_BANDS) if low <= size < high),
                    len(OFFSET_BANDS) - 1,
                )
                target = names.index(injected.joint)
                rows = slice(injected.start_frame, injected.end_frame + 1)
                level = natural.level_deg(family, injected.segment)
                overlap = [
                    [i for i in a.intervals if i.joint == injected.joint
                     and i.start_frame <= injected.end_frame
                     and i.end_frame >= injected.start_frame]
                    for a in analyses
                ]  # fmt: skip
                before = rotation_errors_deg(truth.clean_quats[rows, target],
                                             corrupted.quats[rows, target])  # fmt: skip
                fixed = [
                    int(np.sum(rotation_errors_deg(truth.clean_quats[rows, target],
                                                   a.refined.quats[rows, target])
                               <= 0.2 * before))
                    for a in analyses
                ]  # fmt: skip
                hidden = size <= level
                applied = [any(i.applied for i in o) for o in overlap]
                counts.setdefault((bench_file.rig, band), np.zeros(10, dtype=np.int64))[:] += [
                    1, int(not hidden), int(bool(overlap[1])), int(applied[0]), int(applied[1]),
                    int(hidden and applied[0]), int(hidden and applied[1]),
                    len(before), fixed[0], fixed[1],
                ]  # fmt: skip
    return [
        SmallOffsetRow(rig, OFFSET_BANDS[band], *(int(v) for v in counts[rig, band]))
        for rig in RIGS
        for band in range(len(OFFSET_BANDS))
        if (rig, band) in counts
    ]
