"""Parameters of the two twist detectors: the paper's rule and the robust detector."""

from __future__ import annotations

from dataclasses import dataclass

from mocapqa.errors import InputError
from mocapqa.twist.chain_events import ChainSettings

__all__ = ["PaperParams", "RobustParams"]


@dataclass(frozen=True, slots=True)
class PaperParams:
    """Parameters of the paper's rule.

    Parameters
    ----------
    threshold_deg : float
        τ: both |ΔθP| and |ΔθC| must exceed it (the paper gives no value).
    report_tolerance_deg : float
        Frames whose wrapped offset exceeds this are reported as inside an interval.
    """

    threshold_deg: float = 1.0
    report_tolerance_deg: float = 0.5

    def __post_init__(self) -> None:
        if not (self.threshold_deg >= 0 and self.report_tolerance_deg >= 0):
            raise InputError(
                f"Expected non-negative thresholds, got {self.threshold_deg}, "
                f"{self.report_tolerance_deg}"
            )


@dataclass(frozen=True, slots=True)
class RobustParams:
    """Parameters of the robust detector.

    Parameters
    ----------
    min_threshold_deg : float
        Floor of the jump threshold.
    noise_factor : float
        The threshold is ``max(min_threshold_deg, noise_factor × σ)`` with σ the chain's robust
        (MAD) scale of increment residuals; 0 disables the noise scaling.
    neighbour_s : float
        Time on each side over which the natural velocity is the median of 3 increments per
        side, evenly spaced, seconds (the spacing is at least one frame).
    consistency : float
        Counter-rotation check: ``|wrap(rP + rC)| ≤ consistency × min(|rP|, |rC|)``.
    closure_fraction : float
        Jumps cancel when their net is within ``max(threshold, closure_fraction × largest)``.
    max_interval_s : float
        Longest level shift searched for a release, seconds.
    burst_gap_s : float
        Events closer than this form one burst, seconds.
    agreement : float
        A stretch whose level measured from outside is less than ``agreement`` times the level
        accumulated from its jumps is left unchanged.
    min_fps : float
        Below this frame rate nothing is reported (a flip and a fast roll look alike).
    parent_source : {"increment", "swing_twist"}
        Parent twist from the body-frame increment or from swing–twist angle differences.
    child_source : {"increment", "azimuth", "auto"}
        Child twist from its parent-frame increment, the grandchild azimuth, or the azimuth where
        well-conditioned (``|v⊥| ≥ min_conditioning``) and the increment elsewhere.
    min_conditioning : float
        Sine of the smallest angle between ``v`` and the axis for which the azimuth is used.
    pair_events : bool
        Pair onsets with releases (True) or accumulate every event (False).
    modular : bool
        Compare counter-rotations modulo 2π (True) or require opposite signs (False).
    passes : int
        Detection passes; each later pass re-estimates the natural velocities with the events of
        the previous pass left out.
    speed_factor : float
        A step must also exceed this times the local natural roll speed per frame of the parent
        and of the child (a fast natural roll that reverses moves by about its speed in one
        frame); 0 disables the rule.
    tail_s : float
        Longest decay tail after an interval's last event, seconds (0 disables tails).
    tail_factor : float
        A tail step is a counter-rotated step whose residuals both exceed this times the
        chain's threshold.
    weighted_jumps : bool
        Read each jump as the inverse-variance weighted mean of the parent's step and the
        child's counter-step (True) or as their plain circular mean (False).
    mismatch_noise : float
        Widen the counter-rotation check by this many robust noise scales of ``rP`` and
        ``rC`` combined (0: off; more events are found in noisy chains, and more false ones).
    closure_noise : float
        Two or more events more than ``burst_gap_s`` apart also cancel within this many times
        the root sum of squares of their jumps' uncertainties, each half the gap between the
        parent's step and the child's counter-step (0: off; never inside a burst).
    precision : float
        A stretch whose outside level is below ``agreement`` times its accumulated level is
        left unchanged only when the two differ by more than this many robust scales of the
        roll's deviation from its continuation inside the stretch (0: always); a contradiction
        within the roll's own scatter inside the stretch is no evidence against the jumps.
    mirror : float
        A group of events that pairs a burst with events farther than ``burst_gap_s`` is kept
        only if, between them, the child's level measured from outside mirrors the parent's
        (``|P + C| ≤ mirror × min(|P|, |C|)``); otherwise its bursts stand alone and its lone
        events are left unmatched (0: off).
    ends : bool
        Also report intervals that run to an end of the take: an unmatched onset within
        ``max_interval_s`` of the last frame, or release within it of the first, whose level
        holds to that end (:func:`mocapqa.twist.one_sided.one_sided`).
    end_contrast : float
        Such an event's jump must be at least this many times every raw roll step of the
        parent within ``burst_gap_s`` of it (one event is weaker evidence than an onset and a
        release that cancel).
    end_return : float
        Such an event forms no one-sided interval when, between it and its neighbouring events
        (within ``max_interval_s``) on either side, the parent's roll steps back by its jump
        and the child's by the mirror, each within this fraction of the jump, from one frame to
        the next or over windows of up to ``burst_gap_s`` (the other end of an interior interval
        that made no event; :func:`mocapqa.twist.one_sided.one_sided`). 0: off.
    """

    min_threshold_deg: float = 2.0
    noise_factor: float = 8.0
    neighbour_s: float = 0.1
    consistency: float = 0.5
    closure_fraction: float = 0.2
    max_interval_s: float = 2.0
    burst_gap_s: float = 0.1
    agreement: float = 0.5
    min_fps: float = 10.0
    speed_factor: float = 1.0
    tail_s: float = 0.1
    tail_factor: float = 0.1
    weighted_jumps: bool = False
    mismatch_noise: float = 0.0
    closure_noise: float = 1.0
    precision: float = 2.0
    mirror: float = 0.5
    ends: bool = True
    end_contrast: float = 3.0
    end_return: float = 0.5
    parent_source: str = "increment"
    child_source: str = "increment"
    min_conditioning: float = 0.4
    pair_events: bool = True
    modular: bool = True
    passes: int = 2

    def __post_init__(self) -> None:
        if self.parent_source not in ("increment", "swing_twist"):
            raise InputError(
                f"Expected parent_source 'increment' or 'swing_twist', got {self.parent_source!r}"
            )
        if self.child_source not in ("increment", "azimuth", "auto"):
            raise InputError(
                f"Expected child_source 'increment', 'azimuth' or 'auto', got {self.child_source!r}"
            )
        if self.neighbour_s <= 0 or self.max_interval_s <= 0 or self.passes < 1:
            raise InputError(
                "Expected neighbour_s > 0, max_interval_s > 0 and passes ≥ 1, got "
                f"{self.neighbour_s}, {self.max_interval_s}, {self.passes}"
            )
        if (
            min(self.speed_factor, self.tail_s, self.tail_factor, self.mismatch_noise,
                self.closure_noise, self.precision, self.mirror, self.end_contrast,
                self.end_return) < 0
        ):  # fmt: skip
            raise InputError(
                "Expected speed_factor, tail_s, tail_factor, mismatch_noise, closure_noise, "
                f"precision, mirror, end_contrast and end_return ≥ 0, got {self.speed_factor}, "
                f"{self.tail_s}, {self.tail_factor}, {self.mismatch_noise}, "
                f"{self.closure_noise}, {self.precision}, {self.mirror}, {self.end_contrast}, "
                f"{self.end_return}"
            )
        if self.burst_gap_s <= 0 or self.agreement < 0 or self.min_fps < 0:
            raise InputError(
                "Expected burst_gap_s > 0, agreement ≥ 0 and min_fps ≥ 0, got "
                f"{self.burst_gap_s}, {self.agreement}, {self.min_fps}"
            )

    def neighbour_stride(self, fps: float) -> int:
        """Frames between the 3 samples taken on each side at ``fps`` (``neighbour_s`` / 3)."""
        return max(1, round(self.neighbour_s * fps / 3))

    def chain_settings(self, threshold: float, scale: float, fps: float) -> ChainSettings:
        """How :func:`mocapqa.twist.intervals.chain_intervals` reads the events of a chain
        with jump ``threshold`` and natural roll ``scale`` per frame (radians) at ``fps``."""
        return ChainSettings(
            threshold, scale, fps, self.closure_fraction, self.agreement, self.burst_gap_s,
            self.max_interval_s, self.tail_s, self.precision, self.mirror, self.ends,
            self.end_contrast, self.end_return,
        )  # fmt: skip
