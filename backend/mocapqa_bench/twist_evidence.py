"""What the anatomy evidence changes in the default apply choice, before and after.

"Before" is the calibrated rule alone (probability ≥ ``APPLY_THRESHOLD`` and the
minimum-evidence rule); "after" is :func:`mocapqa.twist.confidence.decide` with the anatomy
evidence of :mod:`mocapqa.twist.anatomy` (the shipped default). Every function returns rows
(dicts of printable values) for ``mocapqa bench twist``:

* :func:`real_error_rows`: on a take with real errors (``005_05``, evaluation only), the
  counter-rotated roll jumps over 20° removed by default, and the frame × chain cells farther
  than 0.25 s from any jump whose roll moves by more than 5° (share and largest);
* :func:`clean_take_rows`: on clean real takes, the intervals applied by default (must stay 0);
* :func:`injected_rows`: on injected takes (level shifts, bursts, clusters: FSR; unpaired
  bursts: jumps removed and far cells moved), default before and after;
* :func:`reliability_rows`: calibrated probability bin → share of intervals that were right,
  over all intervals and over those the anatomy rule applies or blocks;
* :func:`evidence_tables`: all of them on a corpus folder.

Nothing here chooses a parameter; :func:`injected_rows` takes ``min_deg``, ``max_mismatch``,
``max_s`` and ``min_family`` so that the fit takes can compare values (``docs/twist.md``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh
from mocapqa.limits.rig import rig_family
from mocapqa.metrics.twist import rotation_errors_deg
from mocapqa.twist.analysis import TwistAnalysis, analyze_twist
from mocapqa.twist.anatomy import anatomy_evidence
from mocapqa.twist.confidence import (
    ANATOMY_MAX_MISMATCH,
    ANATOMY_MAX_S,
    ANATOMY_MIN_DEG,
    APPLY_THRESHOLD,
    REPETITION_MIN_FAMILY,
    decide,
    has_evidence,
)
from mocapqa.twist.inject import InjectionTruth, inject_twist_errors
from mocapqa.twist.inject_unpaired import inject_unpaired_bursts
from mocapqa.twist.natural_roll import default_natural_roll
from mocapqa.twist.refine import refine_quats
from mocapqa_bench.calibration import real_interval_records, reliability
from mocapqa_bench.natural import natural_error_figures
from mocapqa_bench.twist import (
    REAL_ERROR_TAKES,
    BenchFile,
    find_bench_files,
    interval_records,
    rig_of,
    seeded_injections,
)

__all__ = [
    "EVIDENCE_KINDS",
    "Row",
    "TakeDecisions",
    "clean_take_rows",
    "evidence_tables",
    "injected_rows",
    "real_error_rows",
    "real_reliability_records",
    "reliability_rows",
    "take_decisions",
]

Row = dict[str, str | int | float]
"""One printable table row: column name → value."""

EVIDENCE_KINDS = ("level", "burst", "cluster", "unpaired")
"""Injected shapes measured: the three of :func:`mocapqa.twist.inject.inject_twist_errors` and
unpaired bursts after a natural roll step."""


@dataclass(frozen=True, slots=True)
class TakeDecisions:
    """The default choice on one take, before and after the anatomy evidence.

    Parameters
    ----------
    analysis : TwistAnalysis
        With ``apply="none"``: every interval found, none applied.
    before, after : ndarray of bool, shape (N,)
        Applied by the calibrated rule alone, and by :func:`mocapqa.twist.confidence.decide`.
    rules : tuple of str, length N
        Which evidence decided each interval (after).
    """

    analysis: TwistAnalysis
    before: BoolArray
    after: BoolArray
    rules: tuple[str, ...]

    def refined(self, motion: Motion, chosen: BoolArray) -> TwistAnalysis:
        """The analysis with the ``chosen`` (N,) intervals applied to ``motion``."""
        detected = self.analysis.detected_offsets_rad
        offsets = np.zeros_like(detected)
        for k, interval in enumerate(self.analysis.found):
            if chosen[k]:
                rows = slice(interval.start_frame, interval.end_frame + 1)
                offsets[rows, interval.chain] = detected[rows, interval.chain]
        quats = refine_quats(motion.quats, self.analysis.chains, offsets)
        return replace(
            self.analysis, refined=replace(motion, quats=quats, euler_hint_deg=None),
            offsets_rad=offsets,
        )  # fmt: skip


def take_decisions(
    motion: Motion,
    min_deg: float = ANATOMY_MIN_DEG,
    max_mismatch: float = ANATOMY_MAX_MISMATCH,
    max_s: float = ANATOMY_MAX_S,
    min_family: int = REPETITION_MIN_FAMILY,
) -> TakeDecisions:
    """Every interval of the robust method on ``motion`` and its default choice before and after
    the anatomy evidence (with these parameters; "after" also with the shipped natural roll
    levels, :mod:`mocapqa.twist.natural_roll`)."""
    analysis = analyze_twist(motion, "robust", apply="none")
    found = analysis.found
    probability = np.array([i.confidence for i in found], dtype=np.float64)
    features = [i.features for i in found]
    before = (probability >= APPLY_THRESHOLD) & np.array(
        [has_evidence(f) for f in features], dtype=bool
    )
    anatomy = anatomy_evidence(motion, analysis.chains, found, analysis.detected_offsets_rad)
    chains = [i.chain for i in found]
    family = rig_family(motion.skeleton)
    natural = default_natural_roll()
    natural_deg = [natural.level_deg(family, analysis.chains[i.chain].chain.segment) for i in found]
    after, rules = decide(
        probability,
        features,
        anatomy,
        min_deg,
        max_mismatch,
        max_s,
        chains,
        min_family,
        sides=[i.side for i in found],
        natural_deg=natural_deg,
    )
    return TakeDecisions(analysis, before, after, rules)


def real_error_rows(motion: Motion, take: str) -> list[Row]:
    """Real jumps removed by default and far cells moved, before and after, on a take with real
    errors (evaluation only)."""
    decisions = take_decisions(motion)
    out: list[Row] = []
    for label, chosen in (("before (calibrated)", decisions.before),
                          ("after (with anatomy)", decisions.after),
                          ("apply all", np.ones_like(decisions.before))):  # fmt: skip
        f = natural_error_figures(motion, decisions.refined(motion, chosen))
        out.append(
            {
                "take": take,
                "default": label,
                "intervals applied": f"{int(chosen.sum())} / {len(chosen)}",
                "jumps removed": f"{f.n_removed} / {f.n_jumps}",
                "far cells moved > 5°": f"{f.n_far_moved} / {f.n_far_frames}",
                "far share %": round(100.0 * f.n_far_moved / max(f.n_far_frames, 1), 4),
                "largest far move °": round(f.max_far_move_deg, 1),
            }
        )
    return out


def clean_take_rows(paths: Sequence[Path]) -> list[Row]:
    """Intervals applied by default on clean real takes, before and after (one row per rig and
    one for all; the takes with an interval applied after are named)."""
    counts: dict[str, list[int]] = {}
    named: dict[str, list[str]] = {}
    for path in paths:
        decisions = take_decisions(read_bvh(path))
        take_rig = rig_of(path) or "other"
        for rig in (take_rig, "all"):
            c = counts.setdefault(rig, [0, 0, 0, 0, 0])
            c[0] += 1
            c[1] += int(decisions.before.sum())
            c[2] += int(decisions.after.sum())
            c[3] += int(decisions.before.any())
            c[4] += int(decisions.after.any())
        if decisions.after.any():
            named.setdefault(take_rig, []).append(path.stem)
    return [
        {
            "rig": rig,
            "takes": c[0],
            "intervals applied before": c[1],
            "intervals applied after": c[2],
            "takes with one applied before": c[3],
            "takes with one applied after": c[4],
            "takes (after)": ", ".join(named.get(rig, [])) if rig != "all" else "",
        }
        for rig, c in counts.items()
    ]


def _inject(motion: Motion, rng: np.random.Generator, kind: str) -> tuple[Motion, InjectionTruth]:
    if kind == "unpaired":
        return inject_unpaired_bursts(motion, rng)
    return inject_twist_errors(motion, rng, kind=kind)


def _fsr_counts(
    corrupted: Motion, truth: InjectionTruth, refined: FloatArray
) -> tuple[int, int, float]:
    """Frames of the targets whose error the refinement cut to at most 20 %, all error frames
    (the bench's FSR) and the largest change of a target on its non-injected frames (spill,
    degrees)."""
    good = total = 0
    spill = 0.0
    for target in truth.targets:
        rows = truth.error_mask[:, target]
        clean = truth.clean_quats[rows, target]
        before = rotation_errors_deg(clean, corrupted.quats[rows, target])
        after = rotation_errors_deg(clean, refined[rows, target])
        good += int(np.sum(after <= 0.2 * before))
        total += len(before)
        moved = rotation_errors_deg(truth.clean_quats[~rows, target], refined[~rows, target])
        spill = max(spill, float(moved.max(initial=0.0)))
    return good, total, spill


def injected_rows(
    files: Sequence[BenchFile],
    seed: int = 0,
    repeats: int = 2,
    kinds: Sequence[str] = EVIDENCE_KINDS,
    min_deg: float = ANATOMY_MIN_DEG,
    max_mismatch: float = ANATOMY_MAX_MISMATCH,
    max_s: float = ANATOMY_MAX_S,
    min_family: int = REPETITION_MIN_FAMILY,
    records: list[tuple[str, float, str, bool]] | None = None,
    on_file: Callable[[BenchFile], None] | None = None,
) -> list[Row]:
    """Default before and after on injected takes, per kind.

    Parameters
    ----------
    files : sequence of BenchFile
        The takes (e.g. the held-out ones); seeds ``(seed, crc32(file name), repeat)`` as in
        the bench.
    seed, repeats : int
    kinds : sequence of str
        Among :data:`EVIDENCE_KINDS`.
    min_deg, max_mismatch, max_s, min_family : float or int
        Parameters of :func:`mocapqa.twist.confidence.decide`.
    records : list, optional
        When given, ``(kind, calibrated probability, rule, right)`` of every interval found is
        appended (for :func:`reliability_rows`; right as in the calibration's labels).
    on_file : callable, optional
        Called after each take (progress).

    Returns
    -------
    list of Row
        Per kind: FSR before and after (level shifts, bursts, clusters), or for unpaired
        bursts the jumps over 20° removed and the far cells moved by more than 5°; the largest
        spill onto a target's non-injected frames; intervals applied before and after, right
        and wrong.
    """
    totals: dict[str, np.ndarray] = {k: np.zeros(12, dtype=np.float64) for k in kinds}
    for bench_file in files:
        motion = read_bvh(bench_file.path)
        for kind in kinds:
            inject = functools.partial(_inject, kind=kind)
            injections = seeded_injections(motion, bench_file, seed, repeats, inject)
            for _, corrupted, truth in injections:
                decisions = take_decisions(corrupted, min_deg, max_mismatch, max_s, min_family)
                _add_injection(totals[kind], kind, bench_file, corrupted, truth, decisions, records)
        if on_file is not None:
            on_file(bench_file)
    return [_injected_row(kind, t) for kind, t in totals.items()]


def _add_injection(
    t: np.ndarray, kind: str, bench_file: BenchFile, corrupted: Motion, truth: InjectionTruth,
    decisions: TakeDecisions, records: list[tuple[str, float, str, bool]] | None,
) -> None:  # fmt: skip
    """Add one injected take's figures to the totals ``t`` of its kind (shape (12,), laid out
    as :func:`_injected_row` reads them), and its intervals to ``records`` when given."""
    labels = interval_records(decisions.analysis, truth.offsets_rad, bench_file)
    right = np.array([r.right for r in labels], dtype=bool).reshape(-1)
    if records is not None:
        records += [
            (kind, r.confidence, rule, r.right)
            for r, rule in zip(labels, decisions.rules, strict=True)
        ]
    t[8:12] += [
        np.sum(decisions.before & right), np.sum(decisions.before & ~right),
        np.sum(decisions.after & right), np.sum(decisions.after & ~right),
    ]  # fmt: skip
    for k, chosen in enumerate((decisions.before, decisions.after)):
        refined = decisions.refined(corrupted, chosen)
        if kind == "unpaired":
            f = natural_error_figures(corrupted, refined)
            t[4 * k : 4 * k + 3] += [f.n_removed, f.n_jumps, f.n_far_moved]
            t[4 * k + 3] = max(t[4 * k + 3], f.max_far_move_deg)
        else:
            good, total, spill = _fsr_counts(corrupted, truth, refined.refined.quats)
            t[4 * k : 4 * k + 2] += [good, total]
            t[4 * k + 3] = max(t[4 * k + 3], spill)


def _injected_row(kind: str, t: np.ndarray) -> Row:
    """The row of one kind from its totals: per before and after (``4 * k`` on), FSR frames
    good and all and the largest spill, or for unpaired bursts jumps removed, jumps, far cells
    moved and the largest far move; then intervals applied right and wrong before and after
    (``t[8:12]``)."""
    row: Row = {"kind": kind}
    for k, label in enumerate(("before", "after")):
        if kind == "unpaired":
            row[f"jumps removed {label}"] = f"{int(t[4 * k])} / {int(t[4 * k + 1])}"
            row[f"far cells > 5° {label}"] = f"{int(t[4 * k + 2])} (max {t[4 * k + 3]:.1f}°)"
        else:
            row[f"FSR {label} %"] = round(100.0 * t[4 * k] / max(t[4 * k + 1], 1.0), 2)
            row[f"spill {label} °"] = round(float(t[4 * k + 3]), 1)
    row["applied right / wrong before"] = f"{int(t[8])} / {int(t[9])}"
    row["applied right / wrong after"] = f"{int(t[10])} / {int(t[11])}"
    return row


def reliability_rows(records: Sequence[tuple[str, float, str, bool]], label: str) -> list[Row]:
    """Calibrated probability bin → intervals, mean probability and share right; then the same
    for the intervals the anatomy rule applies (``anatomy``) and blocks (``anatomy_against``)."""
    out: list[Row] = []
    groups = (
        ("all", None),
        ("rule anatomy", "anatomy"),
        ("rule anatomy_against", "anatomy_against"),
    )
    for name, rule in groups:
        rows = [r for r in records if rule is None or r[2] == rule]
        for b in reliability([r[1] for r in rows], [r[3] for r in rows]):
            if b.count == 0:
                continue
            out.append(
                {
                    "set": label,
                    "intervals": name,
                    "probability": f"[{b.low:.1f}, {b.high:.1f}{']' if b.high >= 1.0 else ')'}",
                    "n": b.count,
                    "mean predicted": round(b.mean_probability, 3),
                    "right": round(b.right_share, 3),
                }
            )
    return out


def real_reliability_records(motion: Motion, take: str) -> list[tuple[str, float, str, bool]]:
    """``(take, calibrated probability, rule, right)`` of every interval on a take with real
    errors, right by :func:`mocapqa_bench.calibration.real_interval_records`' rule."""
    labels = real_interval_records(motion, take, "real")
    rules = take_decisions(motion).rules
    return [(take, r.confidence, rule, r.right) for r, rule in zip(labels, rules, strict=True)]


def evidence_tables(
    data_dir: Path,
    seed: int = 0,
    repeats: int = 2,
    on_file: Callable[[BenchFile], None] | None = None,
) -> dict[str, list[Row]]:
    """Every table of this module on a corpus folder (``bvh`` or its parent): the real-error
    take(s), the clean real takes, the held-out injected takes and the reliability tables."""
    files = find_bench_files(data_dir)
    paths = sorted(Path(data_dir).glob("**/*.bvh"))
    real_paths = [p for p in paths if p.name in REAL_ERROR_TAKES]
    real: list[Row] = []
    real_records: list[tuple[str, float, str, bool]] = []
    for path in real_paths:
        motion = read_bvh(path)
        real += real_error_rows(motion, path.stem)
        real_records += real_reliability_records(motion, path.stem)
    held_records: list[tuple[str, float, str, bool]] = []
    held = injected_rows([f for f in files if f.held_out], seed, repeats,
                         records=held_records, on_file=on_file)  # fmt: skip
    return {
        "real errors": real,
        "clean real takes": clean_take_rows([p for p in paths if p.name not in REAL_ERROR_TAKES]),
        "injected, held-out takes": held,
        "reliability, held-out injected": reliability_rows(held_records, "held-out injected"),
        "reliability, real errors": reliability_rows(real_records, "real errors"),
    }
