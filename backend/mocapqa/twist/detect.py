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

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.chain_events import DetectedInterval, IntervalEstimate
from mocapqa.twist.confidence import default_calibration
from mocapqa.twist.detection import (
    MAX_HELD_POSE_FRAMES,
    Detection,
    leading_pose_frames,
    runs,
    shift_detection,
)
from mocapqa.twist.detector_params import PaperParams, RobustParams
from mocapqa.twist.intervals import chain_intervals
from mocapqa.twist.robust_events import event_jumps, robust_residuals

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
    res = robust_residuals(dp, dc, stride, params)
    jumps = event_jumps(res, params)
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
