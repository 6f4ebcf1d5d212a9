"""Intervals that run to an end of the take: an onset with no release, a release with no onset.

An error that runs to the take's last frame has an onset and no release; one that starts before
the take's first frame has a release and no onset. The counter-rotation at that one event is the
same evidence as at an interior onset, so the first or last event of a chain, when it belongs to
no group, lies within ``max_interval_s`` of the take's end and no other event lies within
``burst_gap_s`` of it, forms the interval ``[onset, last frame]`` or ``[first frame, release −
1]`` with the event's jump as its level — when the level holds: next to the event, the parent's
and the child's rolls (taken off their natural travel) step by the jump and its mirror against
the natural side (within ``agreement`` of the jump, and ``|wrap(P + C)| ≤`` :data:`END_MIRROR`
``× min(|P|, |C|)``; the natural side read no farther than the next event there), and the jump
stands out against the parent's steps beside it. A natural step that is not held, or that the
child does not keep counter-rotating, fails that test. Nor does an event whose roll steps back
by its jump (the child mirroring it) between it and the next event on either side, from one
frame to the next or averaged over ``burst_gap_s``: the other end of an interior interval that
made no event.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.chain_events import ChainEvents, IntervalEstimate
from mocapqa.twist.outside import anchors, forbidden_frames

__all__ = ["END_MIRROR", "one_sided"]

END_MIRROR = 0.25
"""Tolerance of the child's mirror at a one-sided interval's event, as a fraction of the
smaller level (half the events' own ``consistency``: one event carries no closure)."""


def one_sided(chain: ChainEvents, groups: list[list[int]]) -> list[IntervalEstimate]:
    """Intervals that run to an end of the take: an onset with no release, a release with no
    onset.

    The chain's last event (a *tail*'s onset) or first event (a *head*'s release) qualifies
    when it belongs to no group, no other event lies within ``burst_gap`` frames of it (the
    onset and release of a returning level shift, :func:`_explained`, do not count) and it
    lies within ``max_frames`` of the take's end on its side; it gives ``[onset, F − 1]`` at
    level ``jump`` or ``[0, release − 1]`` at ``−jump`` when the parent's level next to it
    (:func:`_held_end`) is within ``agreement`` × |jump| of that level and the child's mirrors
    it (``|wrap(P + C)| ≤`` :data:`END_MIRROR` ``× min(|P|, |C|)``), unless it releases a
    burst (:func:`_releases_burst`), an unmatched event cancels it (:func:`_cancels_loose`) or
    its roll steps back where no event was found (:func:`_stepped_back`, ``end_return``). One
    event is weaker evidence than two that cancel, so its jump must also be ``end_contrast``
    times every raw roll step of the parent within ``burst_gap`` frames other than the
    explained events' (the peak of a fast natural roll the child partly counter-rotates is
    no onset; the child's own roll beside it is not compared: a hand turning under a still
    forearm leaves the parent's step a step).

    Parameters
    ----------
    chain : ChainEvents
        The chain's events and rolls (with the child's: none are found without them).
    groups : list of list of int
        Event indices of each interval between events.

    Returns
    -------
    list of IntervalEstimate
        At most one head and one tail; their ``features`` are those of an interior level shift
        whose other end the take cut off: the one end jump, its mismatch, closure 0, the
        disagreement of the held level with the jump, the duration, the level, split 0 and
        unreturned 0.
    """
    settings, frames, jumps, n_frames = chain.settings, chain.frames, chain.jumps, chain.n_frames
    if chain.child_roll is None or len(frames) == 0:
        return []
    parent, child = (chain.roll, chain.natural), chain.child_roll
    burst_gap, max_frames, agreement = settings.burst_gap, settings.max_frames, settings.agreement
    found: list[IntervalEstimate] = []
    grouped = np.zeros(len(frames), dtype=bool)
    grouped[[k for g in groups for k in g]] = True
    # A returning level shift's onset and release are no burst of the end event's.
    explained = frames[[k for g in groups if _explained(chain, g) for k in g]]
    taken = -1
    for side, k in (("tail", len(frames) - 1), ("head", 0)):
        frame = int(frames[k])
        reach = n_frames - frame if side == "tail" else frame
        near = frames[(np.abs(frames - frame) <= burst_gap) & ~np.isin(frames, explained)]
        if k == taken or grouped[k] or len(near) > 1 or reach > max_frames:
            continue
        # The anchor on the event's natural side, moved past the other intervals and events.
        forbidden = forbidden_frames(frames, [*groups, [k]], n_frames, burst_gap)
        before, after = anchors(forbidden, frame, frame)
        jump = float(jumps[k])
        if (
            abs(jump)
            < settings.end_contrast * _largest_step_beside(parent[0], frame, burst_gap, explained)
            or _releases_burst(
                frames, jumps, k, side, burst_gap, max_frames, settings.closure_fraction
            )
            or _cancels_loose(frames, jumps, grouped, k, side, max_frames, agreement)
        ):
            continue
        bounds = _next_events(frames, frame, max_frames)
        stretch, level, p_level, c_level = _held_end(
            parent, child, side, frame, jump, (before, after), burst_gap, bounds
        )
        gap = abs(float(wrap_angle(np.array(p_level - level))))
        mirrored = abs(float(wrap_angle(np.array(p_level + c_level)))) <= END_MIRROR * min(
            abs(p_level), abs(c_level)
        )
        if gap > agreement * abs(level) or not mirrored:
            continue
        if _stepped_back(parent, child, frame, jump, bounds, burst_gap, settings.end_return):
            continue
        taken = k
        features = _features(chain, k, gap, level, stretch.stop - stretch.start)
        found.append(IntervalEstimate(stretch.start, stretch.stop - 1, level, features, side))
    return found


def _explained(chain: ChainEvents, group: list[int]) -> bool:
    """Whether a group of events is a level shift that returns: no two of its events within
    ``burst_gap`` frames of each other, its jumps cancelling (within ``max(threshold,
    closure_fraction × largest)``). Its events are then its onset and release, not steps of a
    burst that an end event next to them would belong to."""
    jumps, settings = chain.jumps[group], chain.settings
    net = abs(float(wrap_angle(np.array(np.sum(jumps)))))
    spread = bool(np.all(np.diff(chain.frames[group]) > settings.burst_gap))
    return spread and net <= max(
        settings.threshold, settings.closure_fraction * float(np.max(np.abs(jumps)))
    )


def _held_level(roll: FloatArray, natural: FloatArray, stretch: slice, reference: slice) -> float:
    """The roll's level over ``stretch`` against its level over ``reference``, each taken off
    its natural travel (the natural increments summed), radians: circular means, wrapped."""
    off = roll - np.cumsum(natural)
    levels = [np.angle(np.mean(np.exp(1j * off[s]))) for s in (stretch, reference)]
    return float(wrap_angle(np.array(levels[0] - levels[1])))


def _stepped_back(
    parent: tuple[FloatArray, FloatArray],
    child: tuple[FloatArray, FloatArray],
    frame: int,
    jump: float,
    bounds: tuple[int, int],
    burst_gap: int,
    tolerance: float,
) -> bool:
    """:func:`_returned` with the step read from one frame to the next, or averaged over
    ``burst_gap`` frames on each side: the averaged levels blur a one-frame counter-rotated
    step where the other roll moves fast (a child rolling 10–17° a frame beside a still
    parent), and a step read over one frame misses a step spread over a few."""
    return any(
        _returned(parent, child, frame, jump, bounds, window, tolerance)
        for window in sorted({1, burst_gap})
    )


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
        Frames averaged on each side of a step (1: the step from one frame to the next).
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


def _features(
    chain: ChainEvents, k: int, gap: float, level: float, length: int
) -> tuple[float, ...]:
    """The features of event ``k``'s one-sided interval of ``length`` frames at ``level``
    whose held level is ``gap`` from it (radians): those of an interior level shift whose
    other end the take cut off."""
    settings = chain.settings
    return (
        float(np.log(abs(float(chain.jumps[k])) / settings.scale)),
        float(chain.mismatch[k]),
        0.0,
        float(min(gap / max(abs(level), settings.threshold), 2.0)),
        float(np.log(length / settings.fps)),
        float(np.log(np.rad2deg(abs(level)))),
        0.0,
        0.0,
    )


def _next_events(frames: IntArray, frame: int, max_frames: int) -> tuple[int, int]:
    """The frames of the events next to ``frame`` on each side, each at most ``max_frames``
    away (that far when there is none)."""
    bounds = (
        int(np.max(frames[frames < frame], initial=frame - max_frames)),
        int(np.min(frames[frames > frame], initial=frame + max_frames)),
    )
    return max(bounds[0], frame - max_frames), min(bounds[1], frame + max_frames)


def _largest_step_beside(
    roll: FloatArray, frame: int, burst_gap: int, explained: IntArray | None = None
) -> float:
    """The largest raw roll step within ``burst_gap`` frames of ``frame`` (its own step and
    those of the ``explained`` event frames left out), radians; 0 when there is none."""
    n_frames = len(roll)
    beside = np.r_[max(frame - burst_gap, 1) : frame, frame + 1 : min(frame + burst_gap + 1,
                                                                        n_frames)]  # fmt: skip
    if explained is not None:
        beside = beside[~np.isin(beside, explained)]
    steps = np.abs(wrap_angle(roll[beside] - roll[beside - 1]))
    return float(np.max(steps, initial=0.0))


def _releases_burst(
    frames: IntArray,
    jumps: FloatArray,
    k: int,
    side: str,
    burst_gap: int,
    max_frames: int,
    closure_fraction: float,
) -> bool:
    """Whether event ``k`` cancels the net jump of the burst next to it (the events before a
    tail's onset, or after a head's release, each within ``burst_gap`` of the next; the
    nearest within ``max_frames``), a burst whose own jumps do not cancel: it is then that
    burst's release (onset), a burst whose last holds made no event."""
    frame, jump = int(frames[k]), float(jumps[k])
    order = np.arange(k - 1, -1, -1) if side == "tail" else np.arange(k + 1, len(frames))
    if not len(order) or abs(int(frames[order[0]]) - frame) > max_frames:
        return False
    burst = order[: 1 + int(np.argmax(np.append(np.abs(np.diff(frames[order])) > burst_gap,
                                                   True)))]  # fmt: skip
    net = float(wrap_angle(np.array(np.sum(jumps[burst]))))
    together = abs(float(wrap_angle(np.array(net + jump))))
    return len(burst) >= 2 and together <= closure_fraction * abs(jump) < abs(net)


def _cancels_loose(
    frames: IntArray,
    jumps: FloatArray,
    grouped: BoolArray,
    k: int,
    side: str,
    max_frames: int,
    agreement: float,
) -> bool:
    """Whether an unmatched event on the side of event ``k`` away from the take's end, within
    ``max_frames``, nearly cancels its jump (within ``agreement`` of the larger): more likely
    the two ends of one interval that read differently than an error running to the end."""
    frame, jump = int(frames[k]), float(jumps[k])
    loose = np.flatnonzero(
        ~grouped
        & (np.abs(frames - frame) <= max_frames)
        & ((frames < frame) == (side == "tail"))
        & (frames != frame)
    )
    sizes = np.maximum(np.abs(jumps[loose]), abs(jump))
    return bool(np.any(np.abs(wrap_angle(jumps[loose] + jump)) <= agreement * sizes))


def _held_end(
    parent: tuple[FloatArray, FloatArray],
    child: tuple[FloatArray, FloatArray],
    side: str,
    frame: int,
    jump: float,
    anchor: tuple[int, int],
    burst_gap: int,
    bounds: tuple[int, int] | None = None,
) -> tuple[slice, float, float, float]:
    """The stretch a one-sided interval at ``frame`` covers, the level its jump implies, and
    the parent's and the child's levels held next to the event.

    The level is read up to ``burst_gap`` frames on each side: on the error side from the
    event on, on the natural side from the anchor (``anchor``: before, after) outwards (a
    single frame may hold a one-frame natural counter-rotation of the child, and far from the
    event the natural travel near the take's end is read less well), never across the next
    event on the natural side (``bounds``: the events next to it, :func:`_next_events`): the
    roll steps there, so the frames beyond it hold another level (the error of a neighbouring
    interval whose release is the frame before a tail's onset).
    """
    n_frames = len(parent[0])
    before, after = anchor
    low, high = (0, n_frames) if bounds is None else (max(bounds[0], 0), min(bounds[1], n_frames))
    if side == "tail":
        stretch, level = slice(frame, n_frames), jump
        held = slice(frame, min(frame + burst_gap, n_frames))
        start = max(before - burst_gap + 1, 0)
        reference = slice(max(start, low) if low <= before else start, before + 1)
    else:
        stretch, level = slice(0, frame), -jump
        held = slice(max(frame - burst_gap, 0), frame)
        stop = min(after + burst_gap, n_frames)
        reference = slice(after, min(stop, high) if high > after else stop)
    p_level, c_level = (_held_level(r, n, held, reference) for r, n in (parent, child))
    return stretch, level, p_level, c_level
