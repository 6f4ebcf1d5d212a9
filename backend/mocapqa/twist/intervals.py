"""Error intervals of one chain from its events, with levels measured from the roll outside them.

Conventions
-----------
* An *event* is a frame where the parent's roll steps away from its natural velocity and the
  child counter-rotates by the same amount (found by :func:`mocapqa.twist.detect.detect_robust`).
  Its *jump* is the size of that step, radians.
* The events that bound each interval are grouped by :mod:`mocapqa.twist.event_groups`
  (matched like brackets, bursts of flips, overlapping groups merged); a burst whose ends do
  not agree still forms an interval, with a lower confidence. With ``ends``, the chain's first
  or last event is freed from its group where it may be a head's release or a tail's onset
  (:mod:`mocapqa.twist.end_pairing`).
* The *natural roll* through an interval is the cubic Hermite continuation of the integrated
  roll between two anchors, with the natural velocities there: the last frame before its first
  event and the frame of its last event (where the roll is back at its natural level), moved
  outwards past any other interval and any other event within ``burst_gap_s``, so that an
  anchor never sits inside another error. Each stretch between two events
  gets one level measured from outside: the circular mean of the raw roll minus that
  continuation. Where the interval's jumps cancel, the level accumulated from its jumps (less
  noisy over long holds) is used instead, unless the outside level is less than ``agreement``
  times it: a stretch whose roll sits near the natural continuation gets level 0 and is left
  bit-identical, so a mismatched pair of events cannot shift clean frames — when that
  contradiction exceeds ``precision`` times the roll's own scatter inside the stretch (a roll
  jittering by more than the level cannot contradict it). Where the jumps do not cancel (a
  burst whose ends disagree), the outside level is used.
* A group that pairs a burst with events far from it is kept only where the child's roll
  mirrors the parent's between them (:func:`mocapqa.twist.outside.split_unmirrored`); the
  bursts of a group split there are marked (feature ``split``), and every interval's
  ``unreturned`` feature reads, from the rolls outside it, how much twist offset its end leaves.
* *One-sided intervals* (:mod:`mocapqa.twist.one_sided`): an error that runs to an end of the
  take has one event, an onset with no release or a release with no onset; with
  ``ends``, such an event that belongs to no group gives an interval to the take's end when
  its level holds.
* The events and settings of a chain, and the intervals read from them, are the types of
  :mod:`mocapqa.twist.chain_events`.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.chain_events import FEATURES, ChainEvents, ChainSettings, IntervalEstimate
from mocapqa.twist.end_pairing import free_ends
from mocapqa.twist.event_groups import closes, event_groups
from mocapqa.twist.one_sided import one_sided
from mocapqa.twist.outside import anchors, forbidden_frames, hermite_deviation, split_unmirrored

__all__ = ["FEATURES", "ChainSettings", "IntervalEstimate", "chain_intervals"]


def _spread(values: FloatArray) -> float:
    """Robust scale (1.4826 × median absolute deviation from the circular mean) of angles."""
    centre = np.angle(np.mean(np.exp(1j * values)))
    return float(1.4826 * np.median(np.abs(wrap_angle(values - centre))))


def _unreturned(
    parent: tuple[FloatArray, FloatArray],
    child: tuple[FloatArray, FloatArray] | None,
    before: int,
    after: int,
) -> float:
    """The counter-rotated part of the net roll change between two anchors, radians (≥ 0).

    Each roll's change from ``before`` to ``after`` beyond its natural velocities; a twist
    offset left at ``after`` moves the parent and the child oppositely, a natural step moves
    one of them (or both alike): the common opposite part, ``min(|P|, |C|)`` when the signs
    differ, else 0. ``parent`` and ``child`` are each (integrated roll, natural increments);
    without the child, 0.
    """
    if child is None:
        return 0.0
    travel = slice(before + 1, after + 1)
    p_net, c_net = (
        float(wrap_angle(np.array(r[after] - r[before] - np.sum(n[travel]))))
        for r, n in (parent, child)
    )
    return min(abs(p_net), abs(c_net)) if p_net * c_net < 0 else 0.0


def chain_intervals(
    frames: IntArray,
    jumps: FloatArray,
    mismatch: FloatArray,
    increments: FloatArray,
    natural: FloatArray,
    settings: ChainSettings,
    small_steps: FloatArray | None = None,
    uncertainty: FloatArray | None = None,
    child: tuple[FloatArray, FloatArray] | None = None,
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
    settings : ChainSettings
        The chain's threshold, scale and frame rate and how its events are read.
    small_steps : ndarray, shape (F,), optional
        Counter-rotated roll steps below the event threshold (0 elsewhere), radians: the
        frames of a decay tail (``settings.tail_s``).
    uncertainty : ndarray, shape (E,), optional
        Uncertainty of each jump, radians: events farther apart than ``burst_gap_s`` cancel
        within the closure tolerance plus the root sum of squares of theirs. None: 0.
    child : tuple of ndarray, optional
        The child's roll increments ΔθC and their natural values, each shape (F,), radians
        (for ``settings.mirror`` and ``settings.ends``).

    Returns
    -------
    offsets : ndarray, shape (F,)
        Level per frame, radians; exactly 0 outside intervals and on stretches at the natural
        level.
    intervals : list of IntervalEstimate
    """
    offsets = np.zeros(len(increments))
    # Frame 0 has no increment, so no event can sit there.
    keep = frames >= 1
    sigma = np.zeros(int(np.sum(keep))) if uncertainty is None else np.asarray(uncertainty)[keep]
    if int(np.sum(keep)) < (1 if settings.ends and child is not None else 2):
        return offsets, []
    chain = ChainEvents(
        frames[keep], jumps[keep], mismatch[keep], sigma, np.cumsum(increments), natural,
        None if child is None else (np.cumsum(child[0]), child[1]), small_steps, settings,
    )  # fmt: skip
    groups = event_groups(chain)
    if settings.ends and chain.child_roll is not None:
        groups = free_ends(chain, groups)
    split = [False] * len(groups)
    if settings.mirror > 0 and chain.child_roll is not None:
        groups, split = split_unmirrored(
            chain.frames, groups, (chain.roll, chain.child_roll[0]),
            (natural, chain.child_roll[1]), settings.burst_gap, settings.mirror,
        )  # fmt: skip
    # Anchors must sit where the roll is at its natural level: outside every interval and
    # away from events that belong to none.
    forbidden = forbidden_frames(chain.frames, groups, chain.n_frames, settings.burst_gap)
    found: list[IntervalEstimate] = []
    for group, is_split in zip(groups, split, strict=True):
        estimate = _group_interval(chain, offsets, group, is_split, forbidden)
        if estimate is not None:
            found.append(estimate)
    if settings.ends:
        for estimate in one_sided(chain, groups):
            offsets[estimate.start_frame : estimate.end_frame + 1] = estimate.offset_rad
            found.append(estimate)
    return offsets, found


def _decay_end(chain: ChainEvents, last: int, last_jump: float) -> int:
    """The last frame of the decay tail after an interval's last event at frame ``last``:
    small counter-rotated steps right after it, in the direction of its jump and adding up to
    less than it, before the next event (``last`` itself when there is none)."""
    frames, small_steps, n_frames = chain.frames, chain.small_steps, chain.n_frames
    later = frames[frames > last]
    stop = min(
        int(later[0]) if len(later) else n_frames, last + chain.settings.tail_frames + 1, n_frames
    )
    end = last
    while (
        end + 1 < stop
        and small_steps is not None
        and small_steps[end + 1] * last_jump > 0
        and abs(small_steps[last + 1 : end + 2].sum()) < abs(last_jump)
    ):
        end += 1
    return end


def _stretch_levels(
    chain: ChainEvents,
    offsets: FloatArray,
    group: list[int],
    deviation: FloatArray,
    before: int,
    net: float,
    closed: bool,
) -> float:
    """Write the level of each stretch between two events of ``group`` into ``offsets`` (where
    it reaches the threshold) and return the largest disagreement between the outside and the
    accumulated level, relative.

    ``deviation`` is the roll's deviation from its natural continuation from frame ``before``
    on; ``net`` the group's net jump (its tail included), ``closed`` whether it cancels.
    """
    events, steps = chain.frames[group], chain.jumps[group]
    accumulated = wrap_angle(np.cumsum(steps - net / len(steps)))[:-1]
    disagreement = 0.0
    for m in range(len(events) - 1):
        lo, hi = int(events[m]), int(events[m + 1])
        outside = float(np.angle(np.mean(np.exp(1j * deviation[lo - before : hi - before]))))
        jumped = float(accumulated[m])
        gap = abs(float(wrap_angle(np.array(outside - jumped))))
        disagreement = max(disagreement, gap / max(abs(jumped), chain.settings.threshold))
        if not closed:
            level = outside
        elif abs(outside) < chain.settings.agreement * abs(
            jumped
        ) and gap > chain.settings.precision * _spread(deviation[lo - before : hi - before]):
            level = 0.0
        else:
            level = jumped
        if abs(level) >= chain.settings.threshold:
            offsets[lo:hi] = level
    return disagreement


def _group_interval(
    chain: ChainEvents,
    offsets: FloatArray,
    group: list[int],
    is_split: bool,
    forbidden: BoolArray,
) -> IntervalEstimate | None:
    """The interval of one group of events, its levels written into ``offsets``; None when
    every stretch of it stays at the natural level."""
    events = chain.frames[group]
    first, last = int(events[0]), int(events[-1])
    steps = chain.jumps[group]
    end = _decay_end(chain, last, steps[-1])
    small_steps = chain.small_steps
    tail = small_steps[last + 1 : end + 1] if small_steps is not None else np.zeros(0)
    before, after = anchors(forbidden, first, end)
    deviation = hermite_deviation(chain.roll, chain.natural, before, after)
    net = float(wrap_angle(np.array(np.sum(steps) + np.sum(tail))))
    spread_out = bool(np.all(np.diff(events) > chain.settings.burst_gap))
    slack = float(np.sqrt(np.sum(chain.sigma[group] ** 2))) if spread_out else 0.0
    largest = float(np.max(np.abs(steps)))
    closed = closes(net, largest, chain.settings.threshold, chain.settings.closure_fraction, slack)
    disagreement = _stretch_levels(chain, offsets, group, deviation, before, net, closed)
    if len(tail) and offsets[last - 1] != 0.0:
        # The level still to go on each tail frame, measured from the tail's end.
        offsets[last:end] = -np.cumsum(tail[::-1])[::-1]
    applied = offsets[first:end]
    nonzero = np.flatnonzero(applied)
    if len(nonzero) == 0:
        return None
    applied = applied[nonzero[0] : nonzero[-1] + 1]
    end_jump = min(abs(float(steps[0])), abs(float(steps[-1])))
    unreturned = _unreturned((chain.roll, chain.natural), chain.child_roll, before, after)
    features = (
        float(np.log(end_jump / chain.settings.scale)),
        float(np.max(chain.mismatch[group])),
        abs(net) / largest,
        float(min(disagreement, 2.0)),
        float(np.log((last - first) / chain.settings.fps)),
        float(np.log(np.rad2deg(np.max(np.abs(applied))))),
        float(is_split),
        unreturned / largest,
    )
    level_mean = float(np.angle(np.mean(np.exp(1j * applied))))
    start, stop = first + int(nonzero[0]), first + int(nonzero[-1])
    return IntervalEstimate(start, stop, level_mean, features)
