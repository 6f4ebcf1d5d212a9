"""The events of one chain and the settings they are read with, and the intervals read from them.

These are the types :mod:`mocapqa.twist.intervals` (intervals between events),
:mod:`mocapqa.twist.one_sided` (intervals that run to an end of the take), the detector
(:mod:`mocapqa.twist.detect`) and the evidence read about its intervals
(:mod:`mocapqa.twist.anatomy`, :mod:`mocapqa.twist.confidence`) share.
"""

from __future__ import annotations

from dataclasses import dataclass

from mocapqa.core.arrays import FloatArray, IntArray

__all__ = ["FEATURES", "ChainEvents", "ChainSettings", "DetectedInterval", "IntervalEstimate"]

FEATURES = (
    "log_jump_ratio",
    "mismatch",
    "closure",
    "disagreement",
    "log_length_s",
    "log_level_deg",
    "split",
    "unreturned",
)
"""Names of the confidence features of an interval, in :attr:`IntervalEstimate.features` order:
log of the smaller end jump over the chain's natural roll scale per frame; largest
counter-rotation mismatch ratio of its events (0 = exact); net jump over largest jump (0 = the
ends agree); largest disagreement between the outside and the accumulated level, relative;
log of the duration in seconds; log of the largest level in degrees; 1 for a burst split off
a group by the mirror check, else 0; the part of the roll's net change across the interval
that the child counter-rotates (a twist offset that has not returned to the natural level,
measured from outside, not from the jumps) over its largest jump."""


@dataclass(frozen=True, slots=True)
class IntervalEstimate:
    """One interval of one chain.

    Parameters
    ----------
    start_frame, end_frame : int
        First and last frame whose roll is offset (inclusive).
    offset_rad : float
        Circular mean of the level over the interval, radians.
    features : tuple of float
        The values named by :data:`FEATURES`.
    side : {"", "head", "tail"}
        "" for an interval between two events; "head" for one from the take's first frame
        to a release with no onset, "tail" for one from an onset with no release to the
        take's last frame.
    """

    start_frame: int
    end_frame: int
    offset_rad: float
    features: tuple[float, ...]
    side: str = ""


@dataclass(frozen=True, slots=True)
class ChainSettings:
    """How :func:`mocapqa.twist.intervals.chain_intervals` reads one chain's events.

    Parameters
    ----------
    threshold : float
        Jump threshold of the chain, radians (also the smallest level applied).
    scale : float
        Natural roll scale of the chain per frame, radians (> 0).
    fps : float
        Frames per second.
    closure_fraction : float
        Jumps cancel when their net is within ``max(threshold, closure_fraction × largest)``.
    agreement : float
        A stretch whose outside level is less than ``agreement`` times its accumulated level is
        left at level 0.
    burst_gap_s, max_interval_s : float
        Largest gap inside a cluster and longest level shift, seconds.
    tail_s : float
        Longest decay tail after an interval's last event, seconds: the run of small steps
        right after the last event, in the direction of its jump and adding up to less than
        it, is the roll returning to its natural level; its frames get the level still to
        go. 0 (or no small steps given) disables tails.
    precision : float
        The ``agreement`` rule leaves a stretch at level 0 only when its outside and
        accumulated levels differ by more than this many robust scales (1.4826 × MAD) of the
        deviation from the continuation inside the stretch; 0: whatever the scatter.
    mirror : float
        With the child's rolls: a group pairing a burst with events far from it is kept only
        if, on every stretch between them, the child's level measured from outside mirrors the
        parent's within this fraction of the smaller; otherwise its bursts stand alone and its
        lone events are left unmatched. 0: off.
    ends : bool
        With the child's rolls: also the intervals that run to an end of the take
        (:func:`mocapqa.twist.one_sided.one_sided`; their tolerances are ``agreement`` and
        :data:`mocapqa.twist.one_sided.END_MIRROR`).
    end_contrast : float
        With ``ends``: smallest ratio of the one event's jump to every raw roll step of the
        parent beside it.
    end_return : float
        With ``ends``: an event whose roll steps back by its jump between it and the next
        other event on either side (within ``max_interval_s``), the parent within this
        fraction of the jump and the child mirroring it, is one end of an interior interval
        whose other end made no event and forms no one-sided interval; 0: no such check.
    """

    threshold: float
    scale: float
    fps: float
    closure_fraction: float
    agreement: float
    burst_gap_s: float
    max_interval_s: float
    tail_s: float = 0.0
    precision: float = 0.0
    mirror: float = 0.0
    ends: bool = False
    end_contrast: float = 3.0
    end_return: float = 0.0

    @property
    def burst_gap(self) -> int:
        """Largest gap inside a cluster, frames (at least 1)."""
        return max(1, round(self.burst_gap_s * self.fps))

    @property
    def max_frames(self) -> int:
        """Longest level shift, frames (at least 2)."""
        return max(2, round(self.max_interval_s * self.fps))

    @property
    def tail_frames(self) -> int:
        """Longest decay tail, frames."""
        return max(0, round(self.tail_s * self.fps))


@dataclass(frozen=True, slots=True)
class ChainEvents:
    """The events and rolls of one chain that the steps of
    :func:`mocapqa.twist.intervals.chain_intervals` share.

    Parameters
    ----------
    frames : ndarray of int, shape (E,)
        Event frames, increasing, all ≥ 1.
    jumps, mismatch, sigma : ndarray, shape (E,)
        Jump of each event (radians), its counter-rotation mismatch ratio and the uncertainty
        of its jump (radians).
    roll, natural : ndarray, shape (F,)
        The parent's integrated roll and its natural roll increments, radians.
    child_roll : tuple of ndarray, each shape (F,), or None
        The child's integrated roll and natural roll increments, radians.
    small_steps : ndarray, shape (F,), or None
        Counter-rotated roll steps below the event threshold (0 elsewhere), radians.
    settings : ChainSettings
    """

    frames: IntArray
    jumps: FloatArray
    mismatch: FloatArray
    sigma: FloatArray
    roll: FloatArray
    natural: FloatArray
    child_roll: tuple[FloatArray, FloatArray] | None
    small_steps: FloatArray | None
    settings: ChainSettings

    @property
    def n_frames(self) -> int:
        """Frames of the take."""
        return len(self.roll)


@dataclass(frozen=True, slots=True)
class DetectedInterval:
    """One error interval on one chain.

    Parameters
    ----------
    chain : int
        Index of the chain.
    start_frame, end_frame : int
        First and last corrupted frame (inclusive).
    offset_rad : float
        Circular mean of the offset over the interval, radians (−π, π].
    confidence : float
        Calibrated probability that applying the interval is right, [0, 1].
    features : tuple of float
        The confidence features (:data:`mocapqa.twist.intervals.FEATURES`; empty for the
        paper's method).
    side : {"", "head", "tail"}
        "head" for an interval from the take's first frame to a release with no onset,
        "tail" for one from an onset with no release to its last frame, else "".
    """

    chain: int
    start_frame: int
    end_frame: int
    offset_rad: float
    confidence: float
    features: tuple[float, ...] = ()
    side: str = ""
