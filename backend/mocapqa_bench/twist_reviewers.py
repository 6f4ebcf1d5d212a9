"""Learning from reviewers, measured leave-one-take-out: the ``--reviewers`` figures of
``mocapqa bench twist``.

The held-back takes of each rig form one "shoot", once per injected error shape
(:data:`KINDS`). Each take gets one injection (:func:`mocapqa_bench.twist.seeded_injections`,
the bench's seeds). For each take left out in turn, a simulated reviewer decides every interval
of the shoot's *other* takes by the truth (accepts a right interval, rejects a wrong one:
:func:`mocapqa_bench.twist.interval_records`), the prior is built from those labels
(:class:`mocapqa.twist.reviewer_prior.ReviewerPrior`), and the left-out take is refined with
the default ``apply="confident"`` with and without it. The figures are the share of right
intervals applied (removal) and of wrong intervals applied (wrong-apply), with 95 % bootstrap
intervals over takes. On ``005_05`` (real errors; evaluation only, never tuning) the reviewer
decides the intervals at even positions by the real-error labels
(:func:`mocapqa_bench.calibration.real_interval_records`) and the default runs on the others.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh
from mocapqa.limits.rig import rig_family
from mocapqa.twist.analysis import TwistAnalysis, analyze_twist
from mocapqa.twist.inject import inject_twist_errors
from mocapqa.twist.reviewer_prior import ReviewerPrior
from mocapqa_bench.twist import RIGS, BenchFile, interval_records, seeded_injections

__all__ = ["ReviewedTake", "leave_one_take_out", "real_take_rows", "reviewed_takes"]

Row = dict[str, Any]

KINDS = ("level", "burst")
"""The injected error shapes of the leave-one-take-out figures (the paper's level shifts, and
bursts of flips, the shape of the real retarget errors)."""


@dataclass(frozen=True, slots=True)
class ReviewedTake:
    """One injected take of a shoot, with its default analysis and the truth of each interval.

    Parameters
    ----------
    rig : str
        Corpus folder (one of :data:`mocapqa_bench.twist.RIGS`).
    kind : str
        The injected error shape (one of :data:`KINDS`).
    family : str
        Rig family of the skeleton (:func:`mocapqa.limits.rig.rig_family`).
    motion : Motion
        The injected take.
    joints : tuple of str
        Joint of each interval of the default analysis.
    right : tuple of bool
        Whether each interval is right.
    applied : tuple of bool
        Whether the default applies each interval (no prior).
    probabilities : tuple of float
        Calibrated probability of each interval, rounded as a run records it.
    """

    rig: str
    kind: str
    family: str
    motion: Motion
    joints: tuple[str, ...]
    right: tuple[bool, ...]
    applied: tuple[bool, ...]
    probabilities: tuple[float, ...]


def _labelled(
    analysis: TwistAnalysis, right: Sequence[bool]
) -> tuple[tuple[str, ...], tuple[bool, ...], tuple[float, ...]]:
    """The joints of an analysis' calibrated intervals (those :func:`interval_records`
    labels, one per ``right``), whether each is applied, and its probability (3 decimals)."""
    kept = [i for i, f in zip(analysis.intervals, analysis.found, strict=True) if f.features]
    if len(kept) != len(right):
        raise ValueError("Expected one label per calibrated interval")
    return (
        tuple(i.joint for i in kept),
        tuple(i.applied for i in kept),
        tuple(round(i.confidence, 3) for i in kept),
    )


def reviewed_takes(
    files: Sequence[BenchFile], seed: int, held_out: bool = True
) -> list[ReviewedTake]:
    """One injected take per file of the held-out side (or, ``held_out=False``, the fit side,
    where the rule was developed) and error shape, analysed with the default, its intervals
    labelled."""
    out = []
    for bench_file in (f for f in files if f.held_out == held_out):
        motion = read_bvh(bench_file.path)
        for kind in KINDS:
            inject = functools.partial(inject_twist_errors, kind=kind)
            for _, corrupted, truth in seeded_injections(motion, bench_file, seed, 1, inject):
                analysis = analyze_twist(corrupted)
                records = interval_records(analysis, truth.offsets_rad, bench_file)
                right = tuple(r.right for r in records)
                joints, applied, probabilities = _labelled(analysis, right)
                family = rig_family(corrupted.skeleton)
                out.append(
                    ReviewedTake(
                        bench_file.rig, kind, family, corrupted, joints, right, applied,
                        probabilities,
                    )
                )  # fmt: skip
    return out


def _prior(takes: Sequence[ReviewedTake], shoot: str, **settings: Any) -> ReviewerPrior:
    """The prior of the truth decisions on every interval of ``takes``."""
    decisions = [
        (t.family, joint, probability, "accept" if right else "reject")
        for t in takes
        for joint, right, probability in zip(t.joints, t.right, t.probabilities, strict=True)
    ]
    return ReviewerPrior.from_decisions(shoot, decisions, **settings)


def _counts(right: Sequence[bool], applied: Sequence[bool]) -> list[int]:
    """[right applied, right, wrong applied, wrong]."""
    r, a = np.asarray(right, dtype=bool), np.asarray(applied, dtype=bool)
    return [int(np.sum(r & a)), int(r.sum()), int(np.sum(~r & a)), int(np.sum(~r))]


def _bootstrap(counts: np.ndarray, column: int, samples: int = 1000) -> tuple[float, float]:
    """95 % interval of the share ``counts[:, column] / counts[:, column + 1]``, resampling
    takes."""
    if len(counts) == 0 or counts[:, column + 1].sum() == 0:
        return float("nan"), float("nan")
    rng = np.random.default_rng(0)
    picks = rng.integers(0, len(counts), size=(samples, len(counts)))
    totals = counts[picks, column + 1].sum(axis=1)
    rates = counts[picks, column].sum(axis=1) / np.maximum(totals, 1)
    low, high = np.quantile(rates[totals > 0], [0.025, 0.975])
    return float(low), float(high)


def _rate_cells(counts: np.ndarray, column: int) -> str:
    """``share % [low–high]`` of a column pair of ``counts``."""
    total = counts[:, column + 1].sum()
    if total == 0:
        return "–"
    low, high = _bootstrap(counts, column)
    return f"{100 * counts[:, column].sum() / total:.1f} % [{100 * low:.0f}–{100 * high:.0f}]"


def leave_one_take_out(takes: Sequence[ReviewedTake], **settings: Any) -> list[Row]:
    """Per rig: removal and wrong-apply rates of the default without and with the prior of the
    other takes' truth decisions, each take left out in turn.

    Returns
    -------
    list of dict
        ``rig``, ``errors`` (the injected shape), ``takes``, ``right``, ``wrong`` and the four
        rates (``%`` with the 95 % bootstrap interval over takes); rigs without takes are left
        out.
    """
    rows = []
    for rig, kind in ((r, k) for r in RIGS for k in KINDS):
        shoot = [t for t in takes if t.rig == rig and t.kind == kind]
        if not shoot:
            continue
        before, after = [], []
        for k, left_out in enumerate(shoot):
            prior = _prior(shoot[:k] + shoot[k + 1 :], f"{rig} {kind}", **settings)
            analysis = analyze_twist(left_out.motion, prior=prior)
            _, applied, _ = _labelled(analysis, left_out.right)
            before.append(_counts(left_out.right, left_out.applied))
            after.append(_counts(left_out.right, applied))
        b = np.array(before, dtype=np.intp).reshape(-1, 4)
        a = np.array(after, dtype=np.intp).reshape(-1, 4)
        rows.append(
            {
                "rig": rig,
                "errors": kind,
                "takes": len(shoot),
                "right": int(b[:, 1].sum()),
                "wrong": int(b[:, 3].sum()),
                "removed, default": _rate_cells(b, 0),
                "removed, with prior": _rate_cells(a, 0),
                "wrong applied, default": _rate_cells(b, 2),
                "wrong applied, with prior": _rate_cells(a, 2),
            }
        )
    return rows


def real_take_rows(path: Path) -> list[Row]:
    """On a real-error take: the reviewer decides the intervals at even positions by their
    real-error labels, the default runs on the others without and with that prior."""
    from mocapqa_bench.calibration import real_interval_records

    motion = read_bvh(path)
    records = real_interval_records(motion, path.name, "iclone")
    default = analyze_twist(motion)
    joints = [i.joint for i in default.intervals]
    probabilities = [round(i.confidence, 3) for i in default.intervals]
    family = rig_family(motion.skeleton)
    decided = [
        (family, joints[k], probabilities[k], "accept" if r.right else "reject")
        for k, r in enumerate(records)
        if k % 2 == 0
    ]
    prior = ReviewerPrior.from_decisions(path.name, decided)
    with_prior = analyze_twist(motion, prior=prior)
    rest = [k for k in range(len(records)) if k % 2 == 1]
    right = [records[k].right for k in rest]
    rows = []
    for label, analysis in (("default", default), ("with prior", with_prior)):
        c = _counts(right, [analysis.intervals[k].applied for k in rest])
        rows.append(
            {
                "take": path.name,
                "run": label,
                "decided": len(decided),
                "accepted": sum(d[3] == "accept" for d in decided),
                "undecided right": f"{c[0]} of {c[1]} applied",
                "undecided wrong": f"{c[2]} of {c[3]} applied",
            }
        )
    return rows
