"""Groups of a chain's events: which events bound one interval, matched like brackets.

Conventions
-----------
* An *event* is a frame where the parent's roll steps away from its natural velocity and the
  child counter-rotates by the same amount (found by :func:`mocapqa.twist.detect.detect_robust`).
  Its *jump* is the size of that step, radians.
* Events are matched like brackets: each event closes the most recent open events whose jumps
  it cancels (net within ``max(threshold, closure_fraction × largest jump)``), within
  ``max_interval_s``. This finds isolated level shifts (onset and release), single-frame flips
  and bursts of flips that return to the natural level. Events left unmatched that lie within
  ``burst_gap_s`` of each other still form a group (a burst whose ends do not agree). A lone
  unmatched event is never a group. A dense burst (events within ``burst_gap_s`` of each other)
  whose jumps cancel as a whole is one group, whatever pairs the bracket matching made inside
  it. Groups whose spans overlap are merged into one.
* The intervals and levels read from the groups are :mod:`mocapqa.twist.intervals`'s; the
  re-pairing of a chain's first or last event is :mod:`mocapqa.twist.end_pairing`'s.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.chain_events import ChainEvents

__all__ = ["closes", "event_groups"]


def closes(
    level: float, largest: float, threshold: float, fraction: float, slack: float = 0.0
) -> bool:
    """Whether a net jump cancels: within ``max(threshold, fraction × largest) + slack``.

    Parameters
    ----------
    level : float
        Net jump of the events read together (wrapped), radians.
    largest : float
        Largest absolute jump among them, radians.
    threshold : float
        The chain's event threshold, radians: nets within it are as good as exact.
    fraction : float
        Closure tolerance as a fraction of ``largest`` (``closure_fraction``), dimensionless.
    slack : float, optional
        Further allowance, radians (the jumps' combined uncertainty); default 0.

    Returns
    -------
    bool
        True when ``|level|`` is within the tolerance.
    """
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


def event_groups(chain: ChainEvents) -> list[list[int]]:
    """Event indices of each interval of a chain, sorted and frame-disjoint.

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
    jumps' uncertainty (``sigma``); flips inside one burst get no such allowance.

    Parameters
    ----------
    chain : ChainEvents
        The chain's events (frames, jumps in radians, their uncertainty) and settings.

    Returns
    -------
    list of list of int
        Indices into the chain's events (shape (E,) arrays) of each group, in frame order.
    """
    frames, burst_gap = chain.frames, chain.settings.burst_gap
    groups, paired = _bracket_groups(chain)
    loose = np.flatnonzero(~paired)
    if len(loose) >= 2:
        cuts = np.flatnonzero(np.diff(frames[loose]) > burst_gap) + 1
        groups += [list(b) for b in np.split(loose, cuts) if len(b) >= 2]
    groups += _cancelling_bursts(chain)
    return _merge_overlapping(frames, groups)


def _bracket_groups(chain: ChainEvents) -> tuple[list[list[int]], BoolArray]:
    """The groups the bracket matching of :func:`event_groups` closes, and which events they hold
    (shape (E,))."""
    frames, jumps, uncertainty = chain.frames, chain.jumps, chain.sigma
    threshold, closure_fraction = chain.settings.threshold, chain.settings.closure_fraction
    burst_gap, max_frames = chain.settings.burst_gap, chain.settings.max_frames
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
            if closes(level, largest, threshold, closure_fraction, slack):
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
    return groups, paired


def _cancelling_bursts(chain: ChainEvents) -> list[list[int]]:
    """Each dense burst (three or more events, each within ``burst_gap`` of the next) whose
    jumps cancel as a whole: one interval, whatever pairs the bracket matching made inside it
    (alternating flips of similar size pair up wrongly)."""
    frames, jumps, settings = chain.frames, chain.jumps, chain.settings
    threshold, closure_fraction = settings.threshold, settings.closure_fraction
    found: list[list[int]] = []
    cuts = np.flatnonzero(np.diff(frames) > settings.burst_gap) + 1
    for burst in np.split(np.arange(len(frames)), cuts):
        largest = float(np.max(np.abs(jumps[burst])))
        net = float(wrap_angle(np.array(np.sum(jumps[burst]))))
        if len(burst) >= 3 and closes(net, largest, threshold, closure_fraction):
            found.append(list(burst))
    return found


def _merge_overlapping(frames: IntArray, groups: list[list[int]]) -> list[list[int]]:
    """``groups`` in frame order, those whose spans overlap merged, each sorted."""
    groups = sorted(groups, key=lambda g: frames[min(g)])
    merged: list[list[int]] = []
    for group in groups:
        if merged and frames[min(group)] < frames[max(merged[-1])]:
            merged[-1] = sorted(set(merged[-1]) | set(group))
        else:
            merged.append(sorted(group))
    return merged
