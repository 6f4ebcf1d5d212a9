"""Re-pairing a chain's first or last event: a head's release or a tail's onset freed from
the group the bracket matching put it in.

Bracket matching (:func:`mocapqa.twist.event_groups.event_groups`) pairs the chain's first
event with a later event whenever their jumps cancel, but near the start that event may be the
release of an error the take began with (a *head*), and at the end the last event the onset of
one it ends in (a *tail*). The events are matched again without that end event, and the new
reading is kept when it pairs the other events better and the freed event then forms its
one-sided interval (:mod:`mocapqa.twist.one_sided`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mocapqa.twist.angles import wrap_angle
from mocapqa.twist.chain_events import ChainEvents
from mocapqa.twist.event_groups import closes, event_groups
from mocapqa.twist.one_sided import one_sided

__all__ = ["free_ends"]


def free_ends(chain: ChainEvents, groups: list[list[int]]) -> list[list[int]]:
    """``groups`` with the first (last) event freed from its group where it may be a head's
    release (a tail's onset, :func:`_without_end`): re-paired only when it then forms that
    one-sided interval.

    Parameters
    ----------
    chain : ChainEvents
        The chain's events and rolls (with the child's, for the one-sided intervals).
    groups : list of list of int
        Event indices of each interval (:func:`mocapqa.twist.event_groups.event_groups`).

    Returns
    -------
    list of list of int
        ``groups``, or the reading without the first and/or last event where it is taken.
    """
    for side, end in (("head", 0), ("tail", len(chain.frames) - 1)):
        if abs(int(chain.frames[end]) - (0 if side == "head" else chain.n_frames)) > (
            chain.settings.max_frames
        ):
            continue
        freed = _without_end(chain, groups, end)
        if freed != groups and any(e.side == side for e in one_sided(chain, freed)):
            groups = freed
    return groups


def _without_end(chain: ChainEvents, groups: list[list[int]], end: int) -> list[list[int]]:
    """``groups`` read again with event ``end`` (the chain's first or last) left out, when that
    reading pairs the other events better; else ``groups``.

    Bracket matching pairs the chain's first event A with a later event B whenever their jumps
    cancel, but near the start A may be the release of an error the take began with and B the
    onset of another interval, whose own release C is then left unmatched or paired with the
    next interval's onset, and so on down the chain (each interval read between the release of
    one error and the onset of the next). Both readings fit the jumps; an onset and the release
    of one error read the same jump twice. The events are matched again without A (the same
    rules, so pairs nested between A and B stay), and that reading is taken when it leaves no
    other event unmatched that the first held, keeps every burst whose flips return together
    (:func:`_bursts`: a run of events each within ``burst_gap`` of the next whose jumps cancel;
    a head's release pairs with a level shift's onset, not with one flip of a burst; the rest of
    the burst's old group may be read again) and its new groups cancel better than the groups it
    replaces (the sum of their net jumps beyond the chain's jump threshold: nets within it are
    as good as exact), or cancels as well and leaves fewer events unexplained
    (:func:`_unexplained`: a head's release and the next onset that cancel within the threshold
    leave that onset's own release unmatched in the middle of the take). The same at the take's
    end, for a tail's onset. The caller keeps it only when the freed event then forms its
    one-sided interval.
    """
    if not any(end in g for g in groups):
        return groups
    keep = np.flatnonzero(np.arange(len(chain.frames)) != end)
    rest = replace(
        chain, frames=chain.frames[keep], jumps=chain.jumps[keep],
        mismatch=chain.mismatch[keep], sigma=chain.sigma[keep],
    )  # fmt: skip
    regrouped = [[int(keep[i]) for i in g] for g in event_groups(rest)]
    held = {k for g in groups for k in g} - {end}
    settings = chain.settings
    bursts = [run for g in groups if end not in g for run in _bursts(chain, g)]
    kept = all(set(run) <= set(h) for run in bursts for h in regrouped if set(run) & set(h))
    if not held <= {k for g in regrouped for k in g} or not kept:
        return groups
    old = [g for g in groups if g not in regrouped]
    new = [g for g in regrouped if g not in groups]

    def residual(chosen: list[list[int]]) -> float:
        nets = [abs(float(wrap_angle(np.array(np.sum(chain.jumps[g]))))) for g in chosen]
        return sum(max(net - settings.threshold, 0.0) for net in nets)

    better = residual(new) < residual(old) or (
        residual(new) <= residual(old)
        and _unexplained(chain, regrouped, end) < _unexplained(chain, groups, end)
    )
    return regrouped if new and better else groups


def _unexplained(chain: ChainEvents, groups: list[list[int]], end: int) -> int:
    """Events other than ``end`` that no group holds and that cannot be the one event of an
    interval running to an end of the take (the chain's first or last event within
    ``max_frames`` of its end): events a reading of the jumps leaves unaccounted for."""
    frames, max_frames = chain.frames, chain.settings.max_frames
    loose = set(range(len(frames))) - {k for g in groups for k in g} - {end}
    if int(frames[0]) <= max_frames:
        loose.discard(0)
    if chain.n_frames - int(frames[-1]) <= max_frames:
        loose.discard(len(frames) - 1)
    return len(loose)


def _bursts(chain: ChainEvents, group: list[int]) -> list[list[int]]:
    """The bursts of ``group`` whose flips return: runs of its events each within
    ``burst_gap`` of the next whose jumps cancel (:func:`mocapqa.twist.event_groups.closes`)."""
    settings = chain.settings
    gaps = np.diff(chain.frames[group]) > settings.burst_gap
    runs = np.split(np.asarray(group), np.flatnonzero(gaps) + 1)
    return [
        [int(k) for k in run] for run in runs
        if len(run) > 1 and closes(float(wrap_angle(np.array(np.sum(chain.jumps[run])))),
                                   float(np.max(np.abs(chain.jumps[run]))), settings.threshold,
                                   settings.closure_fraction)
    ]  # fmt: skip
