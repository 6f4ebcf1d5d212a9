"""The confidence calibration: its fit on the fit takes, its reliability and the real intervals.

* :func:`fit_on_fit_takes` fits :class:`mocapqa.twist.confidence.Calibration` on the interval
  records of the *fit* takes only (never held-out takes, never the real-error take).
* :func:`reliability` bins calibrated probabilities and compares them with how often the
  intervals were right.
* :func:`disagreement_loro` checks the ``MAX_DISAGREEMENT`` rule by leaving one rig out: the
  smallest value of a grid that blocks no right interval on two rigs, and what it blocks on the
  third.
* :func:`real_interval_records` labels the intervals found on a take with real errors: right
  when it holds at least one counter-rotated roll jump over 20° (onset or release), applying it
  alone leaves none of those jumps over 20°, and it moves no frame farther than 0.25 s from
  such a jump by more than 5°.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.twist.analysis import analyze_twist, detect_chains
from mocapqa.twist.confidence import APPLY_THRESHOLD, MIN_LEVEL_DEG, Calibration, fit_calibration
from mocapqa.twist.intervals import FEATURES
from mocapqa_bench.natural import natural_error_figures, natural_jumps
from mocapqa_bench.twist import IntervalRecord

__all__ = [
    "CALIBRATION_KINDS",
    "DisagreementCheck",
    "ReliabilityBin",
    "disagreement_loro",
    "fit_on_fit_takes",
    "real_interval_records",
    "reliability",
]


CALIBRATION_KINDS = ("level", "burst")
"""The injected kinds (besides unpaired bursts) whose intervals the calibration is fitted on.
Clusters (``kind="cluster"``) are left out on purpose: the bench's cluster table then measures
how the calibration carries over to an error layout it was not fitted on."""


@dataclass(frozen=True, slots=True)
class ReliabilityBin:
    """Intervals whose probability falls in ``[low, high)``.

    Parameters
    ----------
    low, high : float
    count : int
    mean_probability : float
    right_share : float
        Share of them that were right.
    """

    low: float
    high: float
    count: int
    mean_probability: float
    right_share: float


@dataclass(frozen=True, slots=True)
class DisagreementCheck:
    """The disagreement limit chosen without one rig, and what it does on that rig.

    Parameters
    ----------
    rig : str
        The rig left out.
    chosen : float or None
        Smallest limit of the grid that blocks no right interval on the other rigs (None: none).
    right_blocked, wrong_blocked, right_applied, wrong_applied : int
        On the rig left out: right and wrong intervals the limit blocks among those applied
        without it (probability ≥ ``APPLY_THRESHOLD``, level ≥ ``MIN_LEVEL_DEG``), and all of
        those.
    """

    rig: str
    chosen: float | None
    right_blocked: int
    wrong_blocked: int
    right_applied: int
    wrong_applied: int


def disagreement_loro(
    records: Sequence[IntervalRecord], grid: Sequence[float] = (1.0, 1.25, 1.5, 1.75)
) -> list[DisagreementCheck]:
    """Leave-one-rig-out check of the ``MAX_DISAGREEMENT`` rule on benchmark interval records."""
    rows = [r for r in records if r.features]
    if not rows:
        return []
    rigs = np.array([r.rig for r in rows])
    features = np.array([r.features for r in rows])
    right = np.array([r.right for r in rows])
    applied = (np.array([r.confidence for r in rows]) >= APPLY_THRESHOLD) & (
        features[:, FEATURES.index("log_level_deg")] >= np.log(MIN_LEVEL_DEG)
    )
    disagreement = features[:, FEATURES.index("disagreement")]
    out = []
    for rig in sorted(set(rigs.tolist())):
        others, mine = rigs != rig, rigs == rig
        free = [d for d in grid if not np.any(others & applied & right & (disagreement >= d))]
        chosen = min(free) if free else None
        blocked = applied & (disagreement >= (chosen if chosen is not None else np.inf))
        out.append(
            DisagreementCheck(
                rig,
                chosen,
                int(np.sum(mine & blocked & right)),
                int(np.sum(mine & blocked & ~right)),
                int(np.sum(mine & applied & right)),
                int(np.sum(mine & applied & ~right)),
            )
        )
    return out


def fit_on_fit_takes(records: Sequence[IntervalRecord], path: Path | None = None) -> Calibration:
    """Fit the calibration on the records of fit (not held-out) takes.

    Raises
    ------
    InputError
        When the fit takes gave too few right or wrong intervals.
    """
    fit = [r for r in records if not r.held_out and r.features]
    if not fit:
        raise InputError("Expected intervals on the fit takes to fit a calibration, got none")
    rigs = sorted({r.rig for r in fit})
    takes = len({(r.rig, r.take) for r in fit})
    description = (
        f"{len(fit)} intervals ({sum(r.right for r in fit)} right) on {takes} fit takes "
        f"({', '.join(rigs)}), injected with level shifts (the paper's protocol), bursts of "
        "flips and unpaired bursts after a natural roll step, and their clean versions"
    )
    return fit_calibration(
        np.array([r.features for r in fit]), [r.right for r in fit], description, path,
        [f"{r.rig}/{r.take}" for r in fit],
    )  # fmt: skip


def reliability(
    probabilities: Sequence[float], right: Sequence[bool], edges: Sequence[float] | None = None
) -> list[ReliabilityBin]:
    """Bins of predicted probability with the observed share of right intervals."""
    p = np.asarray(probabilities, dtype=np.float64)
    y = np.asarray(right, dtype=bool)
    cuts = np.asarray(edges if edges is not None else [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0])
    out = []
    for k in range(len(cuts) - 1):
        last = k == len(cuts) - 2
        inside = (p >= cuts[k]) & ((p <= cuts[k + 1]) if last else (p < cuts[k + 1]))
        count = int(inside.sum())
        out.append(
            ReliabilityBin(
                float(cuts[k]),
                float(cuts[k + 1]),
                count,
                float(p[inside].mean()) if count else float("nan"),
                float(y[inside].mean()) if count else float("nan"),
            )
        )
    return out


def real_interval_records(motion: Motion, take: str, rig: str) -> list[IntervalRecord]:
    """Every interval of the robust method on a take with real errors, labelled (see above)."""
    analysis = analyze_twist(motion, "robust", apply="none")
    jumps = natural_jumps(motion, analysis)
    out = []
    for interval, found in zip(analysis.intervals, analysis.found, strict=True):
        inside = jumps[interval.start_frame : interval.end_frame + 2, found.chain]
        alone = analyze_twist(motion, "robust", apply=frozenset({interval.id}))
        figures = natural_error_figures(motion, alone)
        after = detect_chains(alone.refined.quats, alone.chains, motion.fps, "robust")
        steps = np.rad2deg(np.abs(after.parent_increments[:, found.chain]))
        frames = np.arange(interval.start_frame, interval.end_frame + 2)
        frames = frames[frames < motion.n_frames]
        kept = jumps[frames, found.chain] & (steps[frames] >= 20.0)
        right = bool(inside.any() and not kept.any() and figures.n_far_moved == 0)
        out.append(IntervalRecord(rig, True, take, found.features, interval.confidence, right))
    return out
