"""Detection of axial twist level shifts: candidate frames, offsets and error intervals.

Conventions
-----------
* Works on C chains at once: increments are ``(F, C)`` arrays in radians, wrapped to (−π, π].
* ``offset(t)`` is the parent's twist offset: a corrupted take is ``qP ⊗ R(a, offset)`` with the
  child compensated, so :func:`mocapqa.twist.refine.refine_quats` applies ``R(a, −offset)``.
* ``method="paper"`` is the published rule as written (Kim et al., methods §1): candidates where
  ``ΔθP · ΔθC < 0`` and both magnitudes exceed τ; ``err = sign(ΔθP) · min(|ΔθP|, |ΔθC|)`` is
  accumulated into the offset on every candidate frame, so residues persist to the end of the
  take. Intervals are the runs where the wrapped offset exceeds a reporting tolerance.
* ``method="robust"`` looks for level-shift *events*: frames where the parent's twist increment
  departs from its local natural velocity (the median of its neighbours) by more than a
  threshold scaled to the chain's own noise, and the child counter-rotates by the same amount
  modulo 2π (offsets near ±180° wrap). Each onset is paired with the release that brings the
  accumulated level back to zero within ``max_interval_s``; events left unpaired are ignored,
  so a single spurious event cannot shift the rest of a take — except the first and last
  events near the take's ends, which form an interval to that end when the level holds there
  and the jump stands out (:func:`mocapqa.twist.one_sided.one_sided`).
* Bind-pose first frames (:func:`leading_pose_frames`) are left out of the detection.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.errors import InputError
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.chain_events import DetectedInterval
from mocapqa.twist.confidence import default_calibration
from mocapqa.twist.intervals import ChainSettings, IntervalEstimate, chain_intervals

__all__ = [
    "MAX_HELD_POSE_FRAMES",
    "DetectedInterval",
    "Detection",
    "PaperParams",
    "RobustParams",
    "detect_paper",
    "detect_robust",
    "leading_pose_frames",
    "runs",
    "shift_detection",
]

MAX_HELD_POSE_FRAMES = 240
"""Most leading frames read as one held bind pose (a T-pose held longer is motion)."""


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
        and the child's by the mirror, each within this fraction of the jump, over windows of
        up to ``burst_gap_s`` (the other end of an interior interval that made no event;
        :func:`mocapqa.twist.one_sided.one_sided`). 0: off.
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


@dataclass(frozen=True, slots=True)
class Detection:
    """Detection result for C chains over F frames.

    Parameters
    ----------
    parent_increments : ndarray, shape (F, C)
        ΔθP, radians.
    child_increments : ndarray, shape (F, C)
        ΔθC, radians.
    candidates : ndarray of bool, shape (F, C)
        Candidate (paper) or event (robust) frames.
    offsets : ndarray, shape (F, C)
        offset(t), radians; exactly 0 outside intervals for the robust method.
    intervals : tuple of DetectedInterval
    jumps : ndarray, shape (F, C), optional
        The jump read at each event (robust method), radians, 0 elsewhere; None for the
        paper's method.
    """

    parent_increments: FloatArray
    child_increments: FloatArray
    candidates: BoolArray
    offsets: FloatArray
    intervals: tuple[DetectedInterval, ...]
    jumps: FloatArray | None = None


def runs(mask: BoolArray) -> list[tuple[int, int]]:
    """Inclusive ``(start, end)`` of each run of True in a 1-D mask."""
    padded = np.concatenate(([False], mask, [False])).astype(np.int8)
    edges = np.diff(padded)
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return [(int(s), int(e)) for s, e in zip(starts, ends, strict=True)]


def leading_pose_frames(quats: FloatArray) -> int:
    """How many leading frames of a take are a bind pose rather than motion.

    A bind pose is frame 0, or frame 0 held unchanged for up to :data:`MAX_HELD_POSE_FRAMES`
    frames, followed by a step that :func:`mocapqa.kinematics.bindpose.leading_bind_pose`
    recognises (far larger than any later step of the take).

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Local rotations of the take.

    Returns
    -------
    int
        The number of bind-pose frames (0 when the take starts in motion).
    """
    n_frames = quats.shape[0]
    if n_frames < 3 or quats.shape[1] == 0:
        return 0
    head = quats[: min(n_frames, MAX_HELD_POSE_FRAMES + 1)]
    # Frames equal to frame 0 (to 1e-4° per joint): |q0 · qt| = cos(angle / 2).
    closeness = np.abs(np.einsum("jc,fjc->fj", head[0], head[1:])).min(axis=1)
    moved = np.flatnonzero(closeness < np.cos(np.deg2rad(1e-4) / 2.0))
    if len(moved) == 0:
        return 0
    held = int(moved[0]) + 1
    if held > MAX_HELD_POSE_FRAMES or n_frames - held < 3:
        return 0
    return held if leading_bind_pose(quats[held - 1 :]) else 0


def shift_detection(detection: Detection, skip: int, n_frames: int) -> Detection:
    """A detection made on frames ``skip`` … F − 1 of a take, as one of all ``n_frames`` frames:
    the skipped frames have no increment, no event and no offset; intervals move by ``skip``."""
    if skip == 0:
        return detection

    def pad(values: np.ndarray) -> np.ndarray:
        return np.concatenate([np.zeros((skip, *values.shape[1:]), values.dtype), values])

    return Detection(
        pad(detection.parent_increments), pad(detection.child_increments),
        pad(detection.candidates), pad(detection.offsets),
        tuple(replace(i, start_frame=i.start_frame + skip, end_frame=i.end_frame + skip)
              for i in detection.intervals),
        None if detection.jumps is None else pad(detection.jumps),
    )  # fmt: skip


def _circular_mean(angles: FloatArray) -> float:
    return float(np.angle(np.mean(np.exp(1j * angles))))


def detect_paper(
    parent_increments: FloatArray, child_increments: FloatArray, params: PaperParams
) -> Detection:
    """The paper's candidate rule and cumulative offset.

    Parameters
    ----------
    parent_increments, child_increments : ndarray, shape (F, C)
        ΔθP and ΔθC in radians.
    params : PaperParams

    Returns
    -------
    Detection
    """
    tau = np.deg2rad(params.threshold_deg)
    dp, dc = parent_increments, child_increments
    candidates = (dp * dc < 0) & (np.abs(dp) > tau) & (np.abs(dc) > tau)
    err = np.where(candidates, np.sign(dp) * np.minimum(np.abs(dp), np.abs(dc)), 0.0)
    offsets = np.cumsum(err, axis=0)
    tolerance = np.deg2rad(params.report_tolerance_deg)
    intervals: list[DetectedInterval] = []
    for c in range(offsets.shape[1]):
        wrapped = wrap_angle(offsets[:, c])
        for start, end in runs(np.abs(wrapped) > tolerance):
            level = _circular_mean(wrapped[start : end + 1])
            confidence = float(min(1.0, abs(level) / np.deg2rad(10.0)))
            intervals.append(DetectedInterval(c, start, end, level, confidence))
    return Detection(dp, dc, candidates, offsets, tuple(intervals))


# An optimal sorting network for six values (12 compare–exchanges, depth 5).
_SORT6 = ((0, 5), (1, 3), (2, 4), (1, 2), (3, 4), (0, 3), (2, 5), (0, 1), (2, 3), (4, 5), (1, 2),
          (3, 4))  # fmt: skip


def _neighbour_median(
    increments: FloatArray, stride: int, rows: IntArray | None = None
) -> FloatArray:
    """Median of 6 increments around each frame, 1–3 strides away on each side (itself excluded).

    Edges are mirrored. Of the two middle values the upper is taken. With ``rows``, only those
    frames are computed (shape (R, C)).
    """
    n_frames = increments.shape[0]
    reach = 3 * stride
    padded = np.pad(increments, ((reach, reach), (0, 0)), mode="reflect")
    shifts = [reach + k * stride for k in (-3, -2, -1, 1, 2, 3)]
    if rows is not None:
        return np.sort(padded[rows[:, None] + np.array(shifts)[None, :]], axis=1)[:, 3]
    values = [np.ascontiguousarray(padded[k : k + n_frames]) for k in shifts]
    for i, j in _SORT6:
        low = np.minimum(values[i], values[j])
        values[j] = np.maximum(values[i], values[j])
        values[i] = low
    return values[3]


def _clean_median(
    increments: FloatArray, outliers: BoolArray, stride: int, rows: IntArray, fallback: FloatArray
) -> FloatArray:
    """Median of the non-outlier increments among 6 per side, ``stride`` apart, of ``rows``.

    Of the two middle values the upper is taken. Returns shape (R, C); ``fallback`` where every
    neighbour is an outlier.
    """
    n_frames = increments.shape[0]
    offsets = stride * np.array([k for k in range(-6, 7) if k != 0])
    index = np.clip(rows[:, None] + offsets[None, :], 0, n_frames - 1)
    values = np.where(outliers[index], np.inf, increments[index])  # (R, 2 half, C)
    values.sort(axis=1)
    count = np.sum(~outliers[index], axis=1)  # (R, C)
    upper = np.take_along_axis(values, (count // 2)[:, None, :], axis=1)[:, 0]
    result: FloatArray = np.where(count > 0, upper, fallback)
    return result


def detect_robust(
    parent_increments: FloatArray,
    child_increments: FloatArray,
    fps: float,
    params: RobustParams,
) -> Detection:
    """Level-shift events grouped into intervals whose levels are measured from outside.

    Parameters
    ----------
    parent_increments, child_increments : ndarray, shape (F, C)
        ΔθP and ΔθC in radians.
    fps : float
        Frame rate: every window and duration of ``params`` is in seconds.
    params : RobustParams

    Returns
    -------
    Detection
        ``offsets`` holds every interval found; their ``confidence`` is the calibrated
        probability of :func:`mocapqa.twist.confidence.default_calibration`.
    """
    dp, dc = parent_increments, child_increments
    n_frames, n_chains = dp.shape
    stride = params.neighbour_stride(fps)
    if n_frames <= 2 * 3 * stride + 1 or fps < params.min_fps:
        zeros = np.zeros_like(dp)
        return Detection(dp, dc, zeros.astype(bool), zeros, (), zeros)
    res = _robust_residuals(dp, dc, stride, params)
    jumps = _event_jumps(res, params)
    # Counter-rotated steps below the threshold: where a burst's decay tail shows.
    small = np.zeros_like(dp)
    weak = (res.smaller > params.tail_factor * res.threshold) & res.consistent & ~res.events
    rows_w, cols_w = np.nonzero(weak)
    small[rows_w, cols_w] = np.angle(np.exp(1j * res.rp[weak]) + np.exp(-1j * res.rc[weak]))
    rows, cols = np.nonzero(res.events)
    ratio = np.zeros_like(dp)
    ratio[rows, cols] = res.mismatch[rows, cols] / np.maximum(res.smaller[rows, cols], 1e-12)
    # Each jump is read twice (parent step, child counter-step): half their gap is its error.
    uncertainty = 0.5 * params.closure_noise * res.mismatch
    # The chain's natural roll per frame: noise or typical velocity, whichever is larger.
    roll_scale = np.maximum(
        np.maximum(res.scale, np.median(np.abs(res.natural_p), axis=0)), np.deg2rad(0.01)
    )
    offsets = np.zeros_like(dp)
    found: list[tuple[int, IntervalEstimate]] = []
    for c in range(n_chains):
        frames = np.flatnonzero(res.events[:, c])
        if len(frames) == 0:
            continue
        if params.pair_events:
            settings = params.chain_settings(float(res.threshold[c]), float(roll_scale[c]), fps)
            offsets[:, c], estimates = chain_intervals(
                frames, jumps[frames, c], ratio[frames, c], dp[:, c], res.natural_p[:, c],
                settings, small[:, c], uncertainty[frames, c], (dc[:, c], res.natural_c[:, c]),
            )  # fmt: skip
        else:
            offsets[:, c], estimates = _unpaired_intervals(frames, jumps[frames, c], n_frames)
        found += [(c, e) for e in estimates]
    return Detection(dp, dc, res.events, offsets, _scored(found), jumps)


@dataclass(frozen=True, slots=True)
class _Residuals:
    """The rolls' steps against their natural velocities, and the events they make, each
    shape (F, C) unless noted: the state :func:`detect_robust` reads after its passes.

    ``rp``, ``rc`` are the parent's and the child's residual steps (radians), ``smaller`` the
    smaller of their sizes, ``mismatch`` the size of their sum, ``consistent`` whether that
    mismatch is within the allowed counter-rotation, ``scale`` and ``threshold`` shape (C,)
    the noise scale and jump threshold per chain, ``natural_p``, ``natural_c`` the natural
    velocities.
    """

    rp: FloatArray
    rc: FloatArray
    smaller: FloatArray
    mismatch: FloatArray
    consistent: BoolArray
    scale: FloatArray
    threshold: FloatArray
    events: BoolArray
    natural_p: FloatArray
    natural_c: FloatArray


def _robust_residuals(
    dp: FloatArray, dc: FloatArray, stride: int, params: RobustParams
) -> _Residuals:
    """The events of ``params.passes`` passes, each re-estimating the natural velocities with
    the previous pass's large steps left out."""
    reach = 3 * stride
    floor = np.deg2rad(params.min_threshold_deg)
    natural_p = _neighbour_median(dp, stride)
    natural_c = _neighbour_median(dc, stride)
    for done in range(1, params.passes + 1):
        rp = wrap_angle(dp - natural_p)
        rc = wrap_angle(dc - natural_c)
        smaller = np.minimum(np.abs(rp), np.abs(rc))
        scale = 1.4826 * np.median(smaller, axis=0)
        threshold = np.maximum(floor, params.noise_factor * scale)  # (C,)
        mismatch = np.abs(wrap_angle(rp + rc)) if params.modular else np.abs(rp + rc)
        allowed = params.consistency * smaller
        if params.mismatch_noise > 0:
            # The counter-rotation is read through both rolls' noise: allow that much more.
            noise = 1.4826 * np.hypot(np.median(np.abs(rp), axis=0), np.median(np.abs(rc), axis=0))
            allowed = allowed + params.mismatch_noise * noise
        # A step must also stand out against the roll's own local speed: a fast natural roll
        # that reverses moves by about its speed in one frame.
        local = params.speed_factor * np.maximum(np.abs(natural_p), np.abs(natural_c))
        events = (smaller > np.maximum(threshold, local)) & (mismatch <= allowed)
        if not params.modular:
            events &= rp * rc < 0
        if done == params.passes:
            break
        # Natural velocities again, with the event frames replaced by the residual-free
        # estimate, so that clustered events do not bias each other's neighbours. Only rows
        # within reach of an event can change.
        # Every large step counts as an outlier here (not only consistent events), so that
        # the flips of a burst do not hide each other.
        outliers = np.maximum(np.abs(rp), np.abs(rc)) > threshold
        near = np.flatnonzero(
            np.convolve(outliers.any(axis=1), np.ones(2 * reach + 1), mode="same") > 0
        )
        natural_p = natural_p.copy()
        natural_c = natural_c.copy()
        natural_p[near] = _clean_median(dp, outliers, stride, near, natural_p[near])
        natural_c[near] = _clean_median(dc, outliers, stride, near, natural_c[near])
    return _Residuals(
        rp, rc, smaller, mismatch, mismatch <= allowed, scale, threshold, events, natural_p,
        natural_c,
    )  # fmt: skip


def _event_jumps(res: _Residuals, params: RobustParams) -> FloatArray:
    """The jump of each event (0 elsewhere), radians, shape (F, C)."""
    rp, rc = res.rp, res.rc
    rows, cols = np.nonzero(res.events)
    jumps = np.zeros_like(rp)
    if params.weighted_jumps:
        # Two measurements of one jump: the parent's step and the child's counter-step, each
        # weighted by the inverse variance of its chain's residuals (a jittery parent roll
        # next to a still child is read mostly from the child).
        var_p = (1.4826 * np.median(np.abs(rp), axis=0)) ** 2 + 1e-8
        var_c = (1.4826 * np.median(np.abs(rc), axis=0)) ** 2 + 1e-8
        weight_c = (var_p / (var_p + var_c))[cols]
        gap = wrap_angle(-rc[rows, cols] - rp[rows, cols])
        jumps[rows, cols] = wrap_angle(rp[rows, cols] + weight_c * gap)
    else:
        # The circular mean of the parent's step and the child's counter-step.
        jumps[rows, cols] = np.angle(np.exp(1j * rp[rows, cols]) + np.exp(-1j * rc[rows, cols]))
    return jumps


def _unpaired_intervals(
    frames: IntArray, jumps: FloatArray, n_frames: int
) -> tuple[FloatArray, list[IntervalEstimate]]:
    """Offsets (shape (F,)) and intervals of one chain when events are not paired: the jumps
    accumulated, each run of non-zero level one interval (no features)."""
    steps = np.zeros(n_frames)
    steps[frames] = jumps
    offsets = wrap_angle(np.cumsum(steps))
    offsets[np.abs(offsets) < 1e-12] = 0.0
    estimates = [
        IntervalEstimate(s, e, _circular_mean(offsets[s : e + 1]), ())
        for s, e in runs(offsets != 0.0)
    ]
    return offsets, estimates


def _scored(found: list[tuple[int, IntervalEstimate]]) -> tuple[DetectedInterval, ...]:
    """The chains' intervals with their calibrated probability (0.5 without features)."""
    with_features = [(c, e) for c, e in found if e.features]
    scores: list[float] = (
        default_calibration().probability(np.array([e.features for _, e in with_features])).tolist()
        if with_features
        else []
    )
    probabilities = iter(scores)
    return tuple(
        DetectedInterval(c, e.start_frame, e.end_frame, e.offset_rad,
                         float(next(probabilities)) if e.features else 0.5, e.features, e.side)
        for c, e in found
    )  # fmt: skip
