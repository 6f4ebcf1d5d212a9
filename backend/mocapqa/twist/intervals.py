"""Error intervals of one chain from its events, with levels measured from the roll outside them.

Conventions
-----------
* An *event* is a frame where the parent's roll steps away from its natural velocity and the
  child counter-rotates by the same amount (found by :func:`mocapqa.twist.detect.detect_robust`).
  Its *jump* is the size of that step, radians.
* Events are matched like brackets: each event closes the most recent open events whose jumps
  it cancels (net within ``max(threshold, closure_fraction × largest jump)``), within
  ``max_interval_s``. This finds isolated level shifts (onset and release), single-frame flips
  and bursts of flips that return to the natural level. Events left unmatched that lie within
  ``burst_gap_s`` of each other still form an interval (a burst whose ends do not agree), with a
  lower confidence. A lone unmatched event is never an interval. A dense burst (events within
  ``burst_gap_s`` of each other) whose jumps cancel as a whole is one interval, whatever pairs
  the bracket matching made inside it. Groups whose spans overlap are merged into one.
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
* *One-sided intervals* (:func:`one_sided`): an error that runs to the take's last frame has an
  onset and no release; one that starts before the take's first frame has a release and no
  onset. The counter-rotation at that one event is the same evidence as at an interior onset,
  so the first or last event of a chain, when it belongs to no group, lies within
  ``max_interval_s`` of the take's end and no other event lies within ``burst_gap_s`` of it,
  forms the interval ``[onset, last frame]`` or ``[first frame, release − 1]`` with the event's
  jump as its level — when the level holds: next to the event, the parent's and the child's
  rolls (taken off their natural travel) step by the jump and its mirror against the natural
  side (within ``agreement`` of the jump, and ``|wrap(P + C)| ≤`` :data:`_END_MIRROR` ``×
  min(|P|, |C|)``), and the jump stands out against the parent's steps beside it. A natural
  step that is not held, or that the child does not keep counter-rotating, fails that test.
  Nor does an event whose roll steps back by its jump (the child mirroring it) between it and
  the next event on either side: the other end of an interior interval that made no event.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.outside import anchors, forbidden_frames, hermite_deviation, split_unmirrored

__all__ = ["FEATURES", "IntervalEstimate", "chain_intervals", "one_sided"]

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


def _closes(
    level: float, largest: float, threshold: float, fraction: float, slack: float = 0.0
) -> bool:
    return abs(level) <= max(threshold, fraction * largest) + slack


def _one_onset(
    jumps: FloatArray, stack: list[int], cluster: IntArray, which: int, fraction: float
) -> bool:
    """Whether the open events of cluster ``which`` are one onset and natural steps: at most
    one jump larger than ``fraction`` of the largest. A lone release may close such a cluster
    as a whole (an 85° onset with a 3° roll step in the next frame is a level shift, not a
    burst of flips)."""
    sizes = np.abs(jumps[[i for i in stack if cluster[i] == which]])
    return bool(np.sum(sizes > fraction * sizes.max()) <= 1)


def _groups(
    frames: IntArray,
    jumps: FloatArray,
    threshold: float,
    closure_fraction: float,
    burst_gap: int,
    max_frames: int,
    uncertainty: FloatArray,
) -> list[list[int]]:
    """Event indices of each interval, sorted and frame-disjoint.

    Events are matched like brackets: each new event closes the most recent open events whose
    jumps it cancels (the shortest closure first); open events older than ``max_frames`` are
    dropped. Once two events of one burst (events within ``burst_gap`` frames of each other)
    are open together, they may only be closed from inside that burst, so a burst's last flip
    is never paired with an unrelated event far away. Events left unmatched that lie within
    ``burst_gap`` of each other form a burst. A lone event (none other within ``burst_gap``)
    may close across a burst whose jumps are all within ``closure_fraction`` of its own: such a
    burst is two or more small natural steps inside a large held shift (an arm's roll jittering
    by 3–6° inside a 120° shift), not flips that the lone event could end. Groups whose spans
    overlap (a burst inside a held level shift) are merged. Events farther apart than
    ``burst_gap`` cancel within the closure tolerance plus the root sum of squares of their
    jumps' ``uncertainty``; flips inside one burst get no such allowance.
    """
    groups: list[list[int]] = []
    paired = np.zeros(len(frames), dtype=bool)
    cluster = np.concatenate(([0], np.cumsum(np.diff(frames) > burst_gap)))
    bound = np.zeros(len(frames), dtype=bool)
    alone = np.bincount(cluster)[cluster] == 1
    stack: list[int] = []
    for k in range(len(frames)):
        stack = [i for i in stack if frames[k] - frames[i] <= max_frames]
        level, largest, closed = float(jumps[k]), abs(float(jumps[k])), -1
        # A lone event may close across a burst whose flips are all within its own closure
        # tolerance: small natural steps inside a large held shift, not a burst it could end.
        minor = closure_fraction * largest
        variance = float(uncertainty[k]) ** 2
        for p in range(len(stack) - 1, -1, -1):
            if (
                bound[stack[p]]
                and cluster[stack[p]] != cluster[k]
                and not (alone[k] and abs(float(jumps[stack[p]])) <= minor)
                and not (alone[k] and _one_onset(jumps, stack, cluster, cluster[stack[p]],
                                                 closure_fraction))
            ):  # fmt: skip
                break
            level = float(wrap_angle(np.array(level + jumps[stack[p]])))
            largest = max(largest, abs(float(jumps[stack[p]])))
            variance += float(uncertainty[stack[p]]) ** 2
            slack = np.sqrt(variance) if frames[k] - frames[stack[p]] > burst_gap else 0.0
            if _closes(level, largest, threshold, closure_fraction, slack):
                closed = p
                break
        if closed < 0:
            # Two open events of one burst: the burst's events may only close each other.
            same = [i for i in stack if cluster[i] == cluster[k]]
            if same:
                bound[[*same, k]] = True
            stack.append(k)
            continue
        members = [*stack[closed:], k]
        paired[members] = True
        stack = stack[:closed]
        groups.append(members)
    loose = np.flatnonzero(~paired)
    if len(loose) >= 2:
        cuts = np.flatnonzero(np.diff(frames[loose]) > burst_gap) + 1
        groups += [list(b) for b in np.split(loose, cuts) if len(b) >= 2]
    # A dense burst whose jumps cancel as a whole is one interval, whatever pairs the bracket
    # matching made inside it (alternating flips of similar size pair up wrongly).
    cuts = np.flatnonzero(np.diff(frames) > burst_gap) + 1
    for burst in np.split(np.arange(len(frames)), cuts):
        largest = float(np.max(np.abs(jumps[burst])))
        net = float(wrap_angle(np.array(np.sum(jumps[burst]))))
        if len(burst) >= 3 and _closes(net, largest, threshold, closure_fraction):
            groups.append(list(burst))
    groups.sort(key=lambda g: frames[min(g)])
    merged: list[list[int]] = []
    for group in groups:
        if merged and frames[min(group)] < frames[max(merged[-1])]:
            merged[-1] = sorted(set(merged[-1]) | set(group))
        else:
            merged.append(sorted(group))
    return merged


def _free_first_release(
    frames: IntArray,
    jumps: FloatArray,
    groups: list[list[int]],
    threshold: float,
    closure_fraction: float,
    max_frames: int,
) -> list[list[int]]:
    """Groups with the take's first event freed when it reads better as a release with no
    onset.

    Bracket matching pairs the chain's first event A with the next one B whenever their jumps
    cancel, but near the start A may be the release of an error the take began with and B the
    onset of another interval. When the first group is exactly A and B, A lies within
    ``max_frames`` of frame 0, and a later event C that no group holds, before any other group,
    cancels B (within the closure tolerance) and lies within ``max_frames`` of it, both readings
    fit the jumps: A–B an interval (and C an unmatched event), or A the release of a head and
    B–C an interval. An onset and the release of one error read the same jump twice, so the
    pair that cancels better is taken: B is paired with C, and A left for :func:`one_sided`,
    only when ``|wrap(B + C)| < |wrap(A + B)|``.
    """
    if not groups or groups[0] != [0, 1] or frames[0] > max_frames:
        return groups
    held = {k for g in groups for k in g}
    stop = frames[min(groups[1])] if len(groups) > 1 else np.inf
    for k in range(2, len(frames)):
        if frames[k] > stop or frames[k] - frames[1] > max_frames:
            break
        net = float(wrap_angle(np.array(jumps[1] + jumps[k])))
        largest = max(abs(float(jumps[1])), abs(float(jumps[k])))
        if k not in held and _closes(net, largest, threshold, closure_fraction):
            first = abs(float(wrap_angle(np.array(jumps[0] + jumps[1]))))
            return [[1, k], *groups[1:]] if abs(net) < first else groups
    return groups


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


_END_MIRROR = 0.25
"""Tolerance of the child's mirror at a one-sided interval's event, as a fraction of the
smaller level (half the events' own ``consistency``: one event carries no closure)."""


def _held_level(roll: FloatArray, natural: FloatArray, stretch: slice, reference: slice) -> float:
    """The roll's level over ``stretch`` against its level over ``reference``, each taken off
    its natural travel (the natural increments summed), radians: circular means, wrapped."""
    off = roll - np.cumsum(natural)
    levels = [np.angle(np.mean(np.exp(1j * off[s]))) for s in (stretch, reference)]
    return float(wrap_angle(np.array(levels[0] - levels[1])))


def _returned(
    parent: tuple[FloatArray, FloatArray],
    child: tuple[FloatArray, FloatArray],
    frame: int,
    jump: float,
    bounds: tuple[int, int],
    window: int,
    tolerance: float,
) -> bool:
    """Whether the roll near a lone event steps back by its jump where no event was found: the
    other end of an interior interval, whose counter-rotation was too spread or too jittery to
    make an event.

    An interval's onset and release step by opposite amounts, whichever comes first, so the missed
    end of the event's interval is a step of ``−jump`` on either side of it: inside the stretch a
    one-sided interval would cover (a release after a tail's onset, an onset before a head's
    release, which would move the clean frames beyond it) or on the natural side (the event then
    ends an interior interval; a one-sided interval would move the clean frames before the take's
    end). At every frame ``t`` between ``bounds`` and the event, on either side, the parent's and
    the child's levels over up to ``window`` frames after ``t`` are compared with those over up to
    ``window`` frames before it (never across the event), each roll taken off its natural travel; a
    parent step within ``tolerance`` × |jump| of ``−jump``, with the child's step within the same
    tolerance of ``+jump``, is such an end.

    Parameters
    ----------
    parent, child : tuple of ndarray, each shape (F,)
        Integrated roll and natural roll increments, radians.
    frame : int
        The event's frame (its step is the increment into it).
    jump : float
        The event's jump, radians.
    bounds : tuple of int
        First and last frame (exclusive) searched: the other events next to this one, or the
        farthest frames an interval through it may reach.
    window : int
        Frames averaged on each side of a step.
    tolerance : float
        Largest gap of either step from its target, as a fraction of |jump|; 0: no check.

    Returns
    -------
    bool
    """
    if tolerance <= 0:
        return False
    n_frames = len(parent[0])
    levels = [roll - np.cumsum(natural) for roll, natural in (parent, child)]
    for lo, hi in ((max(bounds[0], 0), frame), (frame, min(bounds[1], n_frames))):
        if hi - lo < 2:
            continue
        t = np.arange(lo + 1, hi)
        start, stop = np.maximum(t - window, lo), np.minimum(t + window, hi)
        ok = np.ones(len(t), dtype=bool)
        for level, target in zip(levels, (-jump, jump), strict=True):
            sums = np.r_[0.0, np.cumsum(level[lo:hi])]
            after = (sums[stop - lo] - sums[t - lo]) / (stop - t)
            before = (sums[t - lo] - sums[start - lo]) / (t - start)
            ok &= np.abs(wrap_angle(after - before - target)) <= tolerance * abs(jump)
        if np.any(ok):
            return True
    return False


def one_sided(
    frames: IntArray,
    jumps: FloatArray,
    mismatch: FloatArray,
    groups: list[list[int]],
    parent: tuple[FloatArray, FloatArray],
    child: tuple[FloatArray, FloatArray],
    threshold: float,
    scale: float,
    fps: float,
    burst_gap: int,
    max_frames: int,
    agreement: float,
    mirror: float,
    contrast: float,
    closure_fraction: float = 0.2,
    returns: float = 0.0,
) -> list[IntervalEstimate]:
    """Intervals that run to an end of the take: an onset with no release, a release with no
    onset.

    The chain's last event (for a *tail*) or first event (for a *head*) qualifies when it
    belongs to no group, no other event lies within ``burst_gap`` frames of it, and it lies
    within ``max_frames`` of the take's end on its side. Its level is held when the parent's
    level over up to ``burst_gap`` frames on the event's error side, against its level over up
    to ``burst_gap`` frames from the anchor on the natural side outwards (the frame before an
    onset, the frame of a release; moved past other intervals and events), each roll taken off
    its natural travel, is within ``agreement`` × |jump| of the level the jump implies, and
    the child's mirrors it (``|wrap(P + C)| ≤ mirror × min(|P|, |C|)``). A held event gives
    the interval ``[onset, F − 1]`` at level ``jump`` or ``[0, release − 1]`` at level
    ``−jump``.

    One event is weaker evidence than an onset and a release that cancel, so the jump must
    also be at least ``contrast`` times every raw roll step of the parent within ``burst_gap``
    frames of it: the peak of a fast natural roll that the child partly counter-rotates (an
    arm rolling 2–9° per frame, its forearm rolling back) is not an onset. The child's own
    roll beside it is not compared: a foot or hand turning under a still calf or forearm does
    not make the parent's step any less of a step.

    Parameters
    ----------
    frames : ndarray of int, shape (E,)
        Event frames, increasing, all ≥ 1.
    jumps, mismatch : ndarray, shape (E,)
        Jump of each event (radians) and its counter-rotation mismatch ratio.
    groups : list of list of int
        Event indices of each interval between events.
    parent, child : tuple of ndarray, each shape (F,)
        Integrated roll and natural roll increments of the parent and of the child, radians.
    threshold, scale : float
        Jump threshold and natural roll scale per frame of the chain, radians.
    fps : float
        Frames per second.
    burst_gap, max_frames : int
        Largest gap inside a cluster and longest level shift, frames.
    agreement, mirror : float
        Tolerances of the held level (fraction of the jump) and of the child's mirror
        (fraction of the smaller level). An unmatched event on the side away from the end,
        within ``max_frames``, whose jump cancels this one's within ``agreement`` of the
        larger also rules it out (the two ends of one interval that read differently).
    contrast : float
        Smallest ratio of the jump to the largest raw roll step of the parent beside it.
    closure_fraction : float
        An event whose jump cancels, to this fraction of its own jump, the net jump of the
        burst next to it on the side away from the take's end (events each within
        ``burst_gap`` of the next, the nearest within ``max_frames``), a burst whose own jumps
        do not cancel, is that burst's release (onset) and forms no one-sided interval.
    returns : float
        An event whose roll steps back by its jump between it and the next other event on
        either side (within ``max_frames``), the parent within this fraction of the jump and
        the child mirroring it, over windows of up to ``burst_gap`` frames, is one end of an
        interior interval whose other end made no event and forms no one-sided interval
        (:func:`_returned`); 0: no such check.

    Returns
    -------
    list of IntervalEstimate
        At most one head and one tail; their ``features`` are those of an interior level shift
        whose other end the take cut off: the one end jump, its mismatch, closure 0, the
        disagreement of the held level with the jump, the duration, the level, split 0 and
        unreturned 0.
    """
    n_frames = len(parent[0])
    found: list[IntervalEstimate] = []
    if len(frames) == 0:
        return found
    grouped = np.zeros(len(frames), dtype=bool)
    grouped[[k for g in groups for k in g]] = True
    taken = -1
    for side, k in (("tail", len(frames) - 1), ("head", 0)):
        frame = int(frames[k])
        reach = n_frames - frame if side == "tail" else frame
        near = frames[np.abs(frames - frame) <= burst_gap]
        if k == taken or grouped[k] or len(near) > 1 or reach > max_frames:
            continue
        # The anchor on the event's natural side, moved past the other intervals and events.
        forbidden = forbidden_frames(frames, [*groups, [k]], n_frames, burst_gap)
        before, after = anchors(forbidden, frame, frame)
        jump = float(jumps[k])
        beside = np.r_[max(frame - burst_gap, 1) : frame, frame + 1 : min(frame + burst_gap + 1,
                                                                            n_frames)]  # fmt: skip
        steps = np.abs(wrap_angle(parent[0][beside] - parent[0][beside - 1]))
        if abs(jump) < contrast * float(np.max(steps, initial=0.0)):
            continue
        # An event that cancels the net jump of the burst next to it (the events before a
        # tail's onset, or after a head's release, each within burst_gap of the next; the
        # nearest within max_frames), a burst whose own jumps do not cancel, is that burst's
        # release (onset): a burst whose last holds made no event.
        order = np.arange(k - 1, -1, -1) if side == "tail" else np.arange(k + 1, len(frames))
        if len(order) and abs(int(frames[order[0]]) - frame) <= max_frames:
            burst = order[: 1 + int(np.argmax(np.append(np.abs(np.diff(frames[order])) > burst_gap,
                                                           True)))]  # fmt: skip
            net = float(wrap_angle(np.array(np.sum(jumps[burst]))))
            together = abs(float(wrap_angle(np.array(net + jump))))
            if len(burst) >= 2 and together <= closure_fraction * abs(jump) < abs(net):
                continue
        # An unmatched event on that side whose jump nearly cancels this one (within
        # ``agreement`` of the larger): more likely the two ends of one interval that read
        # differently than an error running to the take's end.
        loose = np.flatnonzero(
            ~grouped
            & (np.abs(frames - frame) <= max_frames)
            & ((frames < frame) == (side == "tail"))
            & (frames != frame)
        )
        sizes = np.maximum(np.abs(jumps[loose]), abs(jump))
        if np.any(np.abs(wrap_angle(jumps[loose] + jump)) <= agreement * sizes):
            continue
        # The level is read next to the event, up to burst_gap frames on each side: on the
        # error side from the event on, on the natural side from the anchor outwards (a
        # single frame may hold a one-frame natural counter-rotation of the child, and far
        # from the event the natural travel near the take's end is read less well).
        if side == "tail":
            stretch, level = slice(frame, n_frames), jump
            held = slice(frame, min(frame + burst_gap, n_frames))
            reference = slice(max(before - burst_gap + 1, 0), before + 1)
        else:
            stretch, level = slice(0, frame), -jump
            held = slice(max(frame - burst_gap, 0), frame)
            reference = slice(after, min(after + burst_gap, n_frames))
        p_level, c_level = (_held_level(r, n, held, reference) for r, n in (parent, child))
        gap = abs(float(wrap_angle(np.array(p_level - level))))
        mirrored = abs(float(wrap_angle(np.array(p_level + c_level)))) <= mirror * min(
            abs(p_level), abs(c_level)
        )
        if gap > agreement * abs(level) or not mirrored:
            continue
        bounds = (
            int(np.max(frames[frames < frame], initial=frame - max_frames)),
            int(np.min(frames[frames > frame], initial=frame + max_frames)),
        )
        bounds = (max(bounds[0], frame - max_frames), min(bounds[1], frame + max_frames))
        if _returned(parent, child, frame, jump, bounds, burst_gap, returns):
            continue
        taken = k
        features = (
            float(np.log(abs(jump) / scale)),
            float(mismatch[k]),
            0.0,
            float(min(gap / max(abs(level), threshold), 2.0)),
            float(np.log((stretch.stop - stretch.start) / fps)),
            float(np.log(np.rad2deg(abs(level)))),
            0.0,
            0.0,
        )
        found.append(IntervalEstimate(stretch.start, stretch.stop - 1, level, features, side))
    return found


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
    small_steps: FloatArray | None = None,
    tail_s: float = 0.0,
    uncertainty: FloatArray | None = None,
    precision: float = 0.0,
    child: tuple[FloatArray, FloatArray] | None = None,
    mirror: float = 0.0,
    ends: bool = False,
    end_contrast: float = 3.0,
    end_return: float = 0.0,
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
        A stretch whose outside level is less than ``agreement`` times its accumulated level is
        left at level 0.
    burst_gap_s, max_interval_s : float
        Largest gap inside a cluster and longest level shift, seconds.
    small_steps : ndarray, shape (F,), optional
        Counter-rotated roll steps below the event threshold (0 elsewhere), radians: the
        frames of a decay tail.
    tail_s : float
        Longest decay tail after an interval's last event, seconds: the run of small steps
        right after the last event, in the direction of its jump and adding up to less than
        it, is the roll returning to its natural level; its frames get the level still to
        go. 0 (or no ``small_steps``) disables tails.
    uncertainty : ndarray, shape (E,), optional
        Measurement uncertainty of each jump, radians (e.g. half the difference between the
        parent's step and the child's counter-step): events farther apart than
        ``burst_gap_s`` cancel within the closure tolerance plus the root sum of squares of
        their jumps' uncertainties (never inside a burst). None: 0.
    precision : float
        The ``agreement`` rule leaves a stretch at level 0 only when its outside and
        accumulated levels differ by more than this many robust scales (1.4826 × MAD) of the
        deviation from the continuation inside the stretch; 0: whatever the scatter.
    child : tuple of ndarray, optional
        The child's roll increments ΔθC and their natural values, each shape (F,), radians.
    mirror : float
        With ``child``: a group pairing a burst with events far from it is kept only if, on
        every stretch between them, the child's level measured from outside mirrors the
        parent's within this fraction of the smaller; otherwise its bursts stand alone and its
        lone events are left unmatched. 0: off.
    ends : bool
        With ``child``: also the intervals that run to an end of the take
        (:func:`one_sided`; their tolerances are ``agreement`` and :data:`_END_MIRROR`).
    end_contrast : float
        With ``ends``: smallest ratio of the one event's jump to every raw roll step beside it.

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
    # Frame 0 has no increment, so no event can sit there.
    keep = frames >= 1
    frames, jumps, mismatch = frames[keep], jumps[keep], mismatch[keep]
    sigma = np.zeros(len(frames)) if uncertainty is None else np.asarray(uncertainty)[keep]
    if len(frames) < (1 if ends and child is not None else 2):
        return offsets, found
    burst_gap = max(1, round(burst_gap_s * fps))
    max_frames = max(2, round(max_interval_s * fps))
    tail_frames = max(0, round(tail_s * fps)) if small_steps is not None else 0
    roll = np.cumsum(increments)
    groups = _groups(frames, jumps, threshold, closure_fraction, burst_gap, max_frames, sigma)
    child_roll = None if child is None else (np.cumsum(child[0]), child[1])
    if ends and child_roll is not None:
        # A first (last) event paired with the next (previous) one may be a head's release
        # (a tail's onset): re-paired only when it then forms that one-sided interval.
        last = len(frames) - 1
        for side in ("head", "tail"):
            if side == "head":
                freed = _free_first_release(
                    frames, jumps, groups, threshold, closure_fraction, max_frames
                )
            else:
                backwards = _free_first_release(
                    n_frames - 1 - frames[::-1], -jumps[::-1],
                    [[last - k for k in g[::-1]] for g in groups[::-1]],
                    threshold, closure_fraction, max_frames,
                )  # fmt: skip
                freed = [[last - k for k in g[::-1]] for g in backwards[::-1]]
            if freed != groups and any(
                e.side == side
                for e in one_sided(
                    frames, jumps, mismatch, freed, (roll, natural), child_roll, threshold,
                    scale, fps, burst_gap, max_frames, agreement, _END_MIRROR,
                    end_contrast, closure_fraction, end_return,
                )
            ):  # fmt: skip
                groups = freed
    split = [False] * len(groups)
    if mirror > 0 and child_roll is not None:
        groups, split = split_unmirrored(
            frames, groups, (roll, child_roll[0]), (natural, child_roll[1]), burst_gap, mirror
        )
    # Anchors must sit where the roll is at its natural level: outside every interval and
    # away from events that belong to none.
    forbidden = forbidden_frames(frames, groups, n_frames, burst_gap)
    for group, is_split in zip(groups, split, strict=True):
        events = frames[group]
        first, last = int(events[0]), int(events[-1])
        steps = jumps[group]
        # A decay tail: small counter-rotated steps right after the last event, in the
        # direction of its jump, before the next event.
        later = frames[frames > last]
        stop = min(int(later[0]) if len(later) else n_frames, last + tail_frames + 1, n_frames)
        end = last
        while (
            end + 1 < stop
            and small_steps is not None
            and small_steps[end + 1] * steps[-1] > 0
            and abs(small_steps[last + 1 : end + 2].sum()) < abs(steps[-1])
        ):
            end += 1
        tail = small_steps[last + 1 : end + 1] if small_steps is not None else np.zeros(0)
        before, after = anchors(forbidden, first, end)
        deviation = hermite_deviation(roll, natural, before, after)
        net = float(wrap_angle(np.array(np.sum(steps) + np.sum(tail))))
        spread_out = bool(np.all(np.diff(events) > burst_gap))
        slack = float(np.sqrt(np.sum(sigma[group] ** 2))) if spread_out else 0.0
        closed = _closes(net, float(np.max(np.abs(steps))), threshold, closure_fraction, slack)
        accumulated = wrap_angle(np.cumsum(steps - net / len(steps)))[:-1]
        disagreement = 0.0
        for m in range(len(events) - 1):
            lo, hi = int(events[m]), int(events[m + 1])
            outside = float(np.angle(np.mean(np.exp(1j * deviation[lo - before : hi - before]))))
            jumped = float(accumulated[m])
            gap = abs(float(wrap_angle(np.array(outside - jumped))))
            disagreement = max(disagreement, gap / max(abs(jumped), threshold))
            if not closed:
                level = outside
            elif abs(outside) < agreement * abs(jumped) and gap > precision * _spread(
                deviation[lo - before : hi - before]
            ):
                level = 0.0
            else:
                level = jumped
            if abs(level) >= threshold:
                offsets[lo:hi] = level
        if len(tail) and offsets[last - 1] != 0.0:
            # The level still to go on each tail frame, measured from the tail's end.
            offsets[last:end] = -np.cumsum(tail[::-1])[::-1]
        applied = offsets[first:end]
        nonzero = np.flatnonzero(applied)
        if len(nonzero) == 0:
            continue
        applied = applied[nonzero[0] : nonzero[-1] + 1]
        end_jump = min(abs(float(steps[0])), abs(float(steps[-1])))
        unreturned = _unreturned((roll, natural), child_roll, before, after)
        features = (
            float(np.log(end_jump / scale)),
            float(np.max(mismatch[group])),
            abs(net) / float(np.max(np.abs(steps))),
            float(min(disagreement, 2.0)),
            float(np.log((last - first) / fps)),
            float(np.log(np.rad2deg(np.max(np.abs(applied))))),
            float(is_split),
            unreturned / float(np.max(np.abs(steps))),
        )
        level_mean = float(np.angle(np.mean(np.exp(1j * applied))))
        start, end = first + int(nonzero[0]), first + int(nonzero[-1])
        found.append(IntervalEstimate(start, end, level_mean, features))
    if ends and child_roll is not None:
        for estimate in one_sided(
            frames, jumps, mismatch, groups, (roll, natural), child_roll, threshold, scale, fps,
            burst_gap, max_frames, agreement, _END_MIRROR, end_contrast,
            closure_fraction, end_return,
        ):  # fmt: skip
            offsets[estimate.start_frame : estimate.end_frame + 1] = estimate.offset_rad
            found.append(estimate)
    return offsets, found
