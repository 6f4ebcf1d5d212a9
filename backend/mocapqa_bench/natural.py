"""Figures on real twist errors and on real clean takes, and confidence intervals of rates.

* :func:`natural_error_figures`: on a take with real errors (``005_05``), the counter-rotated
  roll jumps over 20° per frame, how many a refinement removed, and how far it moved the roll
  on frames farther than 0.25 s from any such jump (where the raw roll is taken as natural).
* :func:`clean_take_figure`: how many intervals a refinement applies to a real take by default
  and the largest rotation change.
* :func:`wilson_interval`: the Wilson score interval of a success rate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.kinematics.resample import resample_motion
from mocapqa.metrics.twist import rotation_errors_deg
from mocapqa.twist.analysis import TwistAnalysis, analyze_twist, detect_chains
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.spin import find_limb_spins

__all__ = [
    "CLEAN_RATES",
    "CleanTakeFigure",
    "NaturalErrorFigures",
    "clean_figures_at_rates",
    "clean_take_figure",
    "natural_error_figures",
    "natural_jumps",
    "wilson_interval",
]


@dataclass(frozen=True, slots=True)
class NaturalErrorFigures:
    """Real-error figures of one refinement.

    Parameters
    ----------
    n_jumps : int
        Counter-rotated roll jumps over ``jump_deg`` in the raw take (frame × chain).
    n_removed : int
        Of those, how many the refined take no longer has (its roll step there is below
        ``jump_deg``).
    n_removed_strict : int
        How many have a refined roll step of at most 5°.
    n_far_frames : int
        Frame × chain cells farther than ``distance_s`` from every jump of their chain.
    n_far_moved : int
        Of those, cells whose roll the refinement moved by more than ``move_deg``.
    max_far_move_deg : float
        Largest roll move on those cells, degrees.
    """

    n_jumps: int
    n_removed: int
    n_removed_strict: int
    n_far_frames: int
    n_far_moved: int
    max_far_move_deg: float


@dataclass(frozen=True, slots=True)
class CleanTakeFigure:
    """What a default refinement does to a real take.

    Parameters
    ----------
    n_intervals : int
        Intervals found.
    n_applied : int
        Intervals applied by the analysis' apply choice.
    max_change_deg : float
        Largest change of any joint rotation, degrees.
    n_spins, n_flips : int
        Limb spins and flips reported (:mod:`mocapqa.twist.spin`; never applied).
    """

    n_intervals: int
    n_applied: int
    max_change_deg: float
    n_spins: int = 0
    n_flips: int = 0


def natural_jumps(motion: Motion, analysis: TwistAnalysis, jump_deg: float = 20.0) -> BoolArray:
    """Counter-rotated roll jumps over ``jump_deg`` per frame and chain, shape (F, C).

    A jump: ``|ΔθP| > jump_deg``, ``|ΔθC| > jump_deg`` and ``|wrap(ΔθP + ΔθC)|`` at most half
    the smaller, so the child's world orientation hardly moves.
    """
    detection = detect_chains(motion.quats, analysis.chains, motion.fps, "robust")
    dp, dc = detection.parent_increments, detection.child_increments
    limit = np.deg2rad(jump_deg)
    smaller = np.minimum(np.abs(dp), np.abs(dc))
    result: BoolArray = (smaller > limit) & (np.abs(wrap_angle(dp + dc)) <= 0.5 * smaller)
    return result


def natural_error_figures(
    motion: Motion,
    analysis: TwistAnalysis,
    jump_deg: float = 20.0,
    distance_s: float = 0.25,
    move_deg: float = 5.0,
) -> NaturalErrorFigures:
    """Jumps removed and roll moved far from jumps, for a refinement of ``motion``.

    Parameters
    ----------
    motion : Motion
        The raw take.
    analysis : TwistAnalysis
        Its analysis (``analysis.refined`` is the refined take).
    jump_deg, distance_s, move_deg : float
        Jump size, distance from a jump and roll move that count, degrees and seconds.

    Returns
    -------
    NaturalErrorFigures
    """
    jumps = natural_jumps(motion, analysis, jump_deg)
    after = detect_chains(analysis.refined.quats, analysis.chains, motion.fps, "robust")
    step = np.rad2deg(np.abs(after.parent_increments))
    reach = max(0, int(np.floor(distance_s * motion.fps)))
    near = np.zeros_like(jumps)
    for f, c in zip(*np.nonzero(jumps), strict=True):
        near[max(0, f - reach) : f + reach + 1, c] = True
    moved: FloatArray = np.rad2deg(np.abs(wrap_angle(analysis.offsets_rad)))
    far = ~near
    return NaturalErrorFigures(
        n_jumps=int(jumps.sum()),
        n_removed=int(np.sum(jumps & (step < jump_deg))),
        n_removed_strict=int(np.sum(jumps & (step <= 5.0))),
        n_far_frames=int(far.sum()),
        n_far_moved=int(np.sum(far & (moved > move_deg))),
        max_far_move_deg=float(moved[far].max(initial=0.0)),
    )


def clean_take_figure(motion: Motion, analysis: TwistAnalysis) -> CleanTakeFigure:
    """Intervals found and applied, the largest rotation change and the limb spins and flips
    reported, on a real take."""
    change = rotation_errors_deg(motion.quats, analysis.refined.quats)
    shapes = [s.shape for s in find_limb_spins(motion)]
    return CleanTakeFigure(
        n_intervals=len(analysis.intervals),
        n_applied=sum(i.applied for i in analysis.intervals),
        max_change_deg=float(change.max(initial=0.0)),
        n_spins=shapes.count("spin"),
        n_flips=shapes.count("flip"),
    )


CLEAN_RATES = (24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 100.0, 120.0)
"""Frame rates a clean take is resampled to for :func:`clean_figures_at_rates`, frames/s."""


def clean_figures_at_rates(
    motion: Motion, rates: tuple[float, ...] = CLEAN_RATES
) -> list[tuple[float, CleanTakeFigure]]:
    """The default refinement of a clean take resampled to each rate (slerp,
    :func:`mocapqa.kinematics.resample.resample_motion`); the take itself at its own rate
    (within 0.5 frames/s).

    Returns
    -------
    list of (float, CleanTakeFigure)
        Rate (frames/s) and what the defaults did at it: a clean take should get no interval
        applied at any rate.
    """
    out = []
    for fps in rates:
        take = motion if abs(fps - motion.fps) <= 0.5 else resample_motion(motion, fps)
        out.append((fps, clean_take_figure(take, analyze_twist(take))))
    return out


def wilson_interval(successes: int, total: int, z: float = 1.96) -> tuple[float, float]:
    """Wilson score interval of ``successes / total`` (95 % for z = 1.96); (0, 1) for none."""
    if total <= 0:
        return 0.0, 1.0
    p = successes / total
    denominator = 1.0 + z * z / total
    centre = (p + z * z / (2 * total)) / denominator
    half = z * np.sqrt(p * (1 - p) / total + z * z / (4 * total * total)) / denominator
    return float(max(0.0, centre - half)), float(min(1.0, centre + half))
