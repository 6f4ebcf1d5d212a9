"""Error intervals of one chain from its events, with levels measured from the roll outside them.

Conventions
-----------
* An *event* is a frame where the parent's roll steps away from its natural velocity and the
  child counter-rotates by the same amount (found by :func:`mocapqa.twist.detect.detect_robust`).
  Its *jump* is the size of that step, radians.
* Events closer than ``burst_gap_s`` form a *cluster* (a burst of flips, or one edge of a level
  shift). A cluster whose jumps cancel (net within ``max(threshold, closure_fraction × largest
  jump)``) is an interval by itself (single-frame flips, bursts that return to the natural
  level). Other clusters are paired like brackets with a later cluster whose net jump cancels
  theirs (within ``max(threshold / 2, closure_fraction × larger net)``), within
  ``max_interval_s`` (a level shift held for a while). A
  cluster of two or more events that finds no partner is still an interval (a burst whose ends
  do not agree), with a lower confidence. A lone unpaired event is never an interval.
* The *natural roll* through an interval is the cubic Hermite continuation of the integrated
  roll between the frame before its first event and its last event (where the roll is back at
  its natural level), with the natural velocities at both ends. Each stretch between two events
  gets one level: the circular mean of the raw roll minus that continuation. The level from
  accumulating jump sizes is used only where it agrees with the outside one (it is less noisy);
  a stretch whose roll sits on the natural continuation gets level 0 and is left bit-identical,
  so a mismatched pair of events cannot shift clean frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle

__all__ = ["FEATURES", "IntervalEstimate", "chain_intervals"]

FEATURES = (
    "log_jump_ratio",
    "mismatch",
    "closure",
    "disagreement",
    "log_length_s",
    "log_level_deg",
)
"""Names of the confidence features of an interval, in :attr:`IntervalEstimate.features` order:
log of the smaller end jump over the chain's natural roll scale per frame; largest
counter-rotation mismatch ratio of its events (0 = exact); net jump over largest jump (0 = the
ends agree); largest disagreement between the outside and the accumulated level, relative;
log of the duration in seconds; log of the largest level in degrees."""


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
    """

    start_frame: int
    end_frame: int
    offset_rad: float
    features: tuple[float, ...]


def _closes(level: float, largest: float, threshold: float, fraction: float) -> bool:
    return abs(level) <= max(threshold, fraction * largest)


def _groups(
    frames: IntArray,
    jumps: FloatArray,
    threshold: float,
    closure_fraction: float,
    burst_gap: int,
    max_frames: int,
) -> list[list[int]]:
    """Event indices of each interval, sorted and frame-disjoint."""
    cuts = np.flatnonzero(np.diff(frames) > burst_gap) + 1
    clusters = [list(c) for c in np.split(np.arange(len(frames)), cuts)]
    nets = [float(wrap_angle(np.array(np.sum(jumps[c])))) for c in clusters]
    largest = [float(np.max(np.abs(jumps[c]))) for c in clusters]
    groups: list[list[int]] = []
    used = [False] * len(clusters)
    stack: list[int] = []
    for k, members in enumerate(clusters):
        if len(members) >= 2 and _closes(nets[k], largest[k], threshold, closure_fraction):
            groups.append(members)
            used[k] = True
            continue
        start = frames[members[0]]
        stack = [p for p in stack if start - frames[clusters[p][-1]] <= max_frames]
        # Clusters pair when their net jumps cancel, relative to the nets themselves (not to
        # the largest flip inside a burst, which would let a small unrelated event close it).
        level, big, closed = nets[k], abs(nets[k]), -1
        for p in range(len(stack) - 1, -1, -1):
            level = float(wrap_angle(np.array(level + nets[stack[p]])))
            big = max(big, abs(nets[stack[p]]))
            if _closes(level, big, 0.5 * threshold, closure_fraction):
                closed = p
                break
        if closed < 0:
            stack.append(k)
            continue
        joined = [i for p in stack[closed:] for i in clusters[p]] + members
        for p in stack[closed:]:
            used[p] = True
        used[k] = True
        stack = stack[:closed]
        groups.append(joined)
    groups += [c for k, c in enumerate(clusters) if not used[k] and len(c) >= 2]
    # Merge groups whose frame spans overlap (a burst inside a held level shift).
    groups.sort(key=lambda g: frames[g[0]])
    merged: list[list[int]] = []
    for group in groups:
        if merged and frames[group[0]] < frames[merged[-1][-1]]:
            merged[-1] = sorted(set(merged[-1]) | set(group))
        else:
            merged.append(sorted(group))
    return merged


def chain_intervals(
    frames: IntArray,
    jumps: FloatArray,
    mismatch: FloatArray,
    increments: FloatArray,
    natural: FloatArray,
    threshold: float,
    scale: float,
    fps: float,
    closure_fraction: float,
    agreement: float,
    burst_gap_s: float,
    max_interval_s: float,
) -> tuple[FloatArray, list[IntervalEstimate]]:
    """Offsets and intervals of one chain.

    Parameters
    ----------
    frames : ndarray of int, shape (E,)
        Event frames, increasing.
    jumps : ndarray, shape (E,)
        Jump of each event, radians.
    mismatch : ndarray, shape (E,)
        Counter-rotation mismatch of each event over its smaller residual (0 = exact).
    increments : ndarray, shape (F,)
        The parent's roll increments ΔθP, radians.
    natural : ndarray, shape (F,)
        Natural roll increment per frame (events left out), radians.
    threshold : float
        Jump threshold of the chain, radians (also the smallest level applied).
    scale : float
        Natural roll scale of the chain per frame, radians (> 0).
    fps : float
        Frames per second.
    closure_fraction : float
        Jumps cancel when their net is within ``max(threshold, closure_fraction × largest)``.
    agreement : float
        The accumulated level is used where it is within
        ``max(2 threshold, agreement × |level|)`` of the outside level.
    burst_gap_s, max_interval_s : float
        Largest gap inside a cluster and longest level shift, seconds.

    Returns
    -------
    offsets : ndarray, shape (F,)
        Level per frame, radians; exactly 0 outside intervals and on stretches at the natural
        level.
    intervals : list of IntervalEstimate
    """
    n_frames = len(increments)
    offsets = np.zeros(n_frames)
    found: list[IntervalEstimate] = []
    if len(frames) < 2:
        return offsets, found
    burst_gap = max(1, round(burst_gap_s * fps))
    max_frames = max(2, round(max_interval_s * fps))
    roll = np.cumsum(increments)
    for group in _groups(frames, jumps, threshold, closure_fraction, burst_gap, max_frames):
        events = frames[group]
        first, last = int(events[0]), int(events[-1])
        before = first - 1
        span = last - before
        # The natural roll's travel from the anchor before to the last event, modulo 2π.
        travel = float(np.sum(natural[first : last + 1]))
        end_value = roll[before] + travel + wrap_angle(roll[last] - roll[before] - travel)
        u = np.arange(span + 1) / span
        h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
        h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
        continuation = (
            h00 * roll[before]
            + h10 * span * natural[first]
            + h01 * end_value
            + h11 * span * natural[last]
        )
        deviation = wrap_angle(roll[before : last + 1] - continuation)
        steps = jumps[group]
        net = float(wrap_angle(np.array(np.sum(steps))))
        accumulated = wrap_angle(np.cumsum(steps - net / len(steps)))[:-1]
        disagreement = 0.0
        for m in range(len(events) - 1):
            lo, hi = int(events[m]), int(events[m + 1])
            outside = float(np.angle(np.mean(np.exp(1j * deviation[lo - before : hi - before]))))
            jumped = float(accumulated[m])
            gap = abs(float(wrap_angle(np.array(outside - jumped))))
            disagreement = max(disagreement, gap / max(abs(jumped), threshold))
            level = jumped if gap <= max(2 * threshold, agreement * abs(jumped)) else outside
            if abs(level) >= threshold:
                offsets[lo:hi] = level
        applied = offsets[first:last]
        nonzero = np.flatnonzero(applied)
        if len(nonzero) == 0:
            continue
        applied = applied[nonzero[0] : nonzero[-1] + 1]
        ends = min(abs(float(steps[0])), abs(float(steps[-1])))
        features = (
            float(np.log(ends / scale)),
            float(np.max(mismatch[group])),
            abs(net) / float(np.max(np.abs(steps))),
            float(min(disagreement, 2.0)),
            float(np.log((last - first) / fps)),
            float(np.log(np.rad2deg(np.max(np.abs(applied))))),
        )
        level_mean = float(np.angle(np.mean(np.exp(1j * applied))))
        start, end = first + int(nonzero[0]), first + int(nonzero[-1])
        found.append(IntervalEstimate(start, end, level_mean, features))
    return offsets, found
