"""The roll's natural level read from outside an interval, and the mirror check of its child.

* *Anchors* are frames where the roll is at its natural level: outside every group of events
  and away from events that belong to none.
* The natural roll between two anchors is the cubic Hermite continuation of the integrated
  roll with the natural velocities there.
* A group of events that pairs a burst with events far from it is kept only where the child's
  roll mirrors the parent's between them.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.twist.angles import wrap_angle

__all__ = ["anchors", "forbidden_frames", "hermite_deviation", "split_unmirrored"]


def hermite_deviation(roll: FloatArray, natural: FloatArray, before: int, after: int) -> FloatArray:
    """The roll minus its cubic Hermite continuation between two anchors, frames before…after.

    The continuation joins the integrated roll at the anchors with the natural velocities
    there; its travel between them is taken modulo 2π.

    Parameters
    ----------
    roll : ndarray, shape (F,)
        Integrated roll (cumulative sum of the increments), radians.
    natural : ndarray, shape (F,)
        Natural roll increment per frame, radians.
    before, after : int
        Anchor frames, ``before < after``.

    Returns
    -------
    ndarray, shape (after − before + 1,)
        Wrapped deviation, radians (0 at both anchors).
    """
    span = after - before
    travel = float(np.sum(natural[before + 1 : after + 1]))
    end_value = roll[before] + travel + wrap_angle(roll[after] - roll[before] - travel)
    u = np.arange(span + 1) / span
    h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
    h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
    continuation = (
        h00 * roll[before] + h10 * span * natural[before] + h01 * end_value
        + h11 * span * natural[after]
    )  # fmt: skip
    result: FloatArray = wrap_angle(roll[before : after + 1] - continuation)
    return result


def forbidden_frames(
    frames: IntArray, groups: list[list[int]], n_frames: int, burst_gap: int
) -> BoolArray:
    """Frames where no anchor may sit: inside every group, and near events of none.

    Parameters
    ----------
    frames : ndarray of int, shape (E,)
        Event frames, increasing.
    groups : list of list of int
        Event indices of each group, sorted.
    n_frames : int
        Frames of the take.
    burst_gap : int
        Frames on each side of an event of no group where no anchor may sit.

    Returns
    -------
    ndarray of bool, shape (F,)
    """
    forbidden = np.zeros(n_frames, dtype=bool)
    for group in groups:
        forbidden[frames[group[0]] : frames[group[-1]]] = True
    grouped = np.zeros(len(frames), dtype=bool)
    grouped[[k for g in groups for k in g]] = True
    for f in frames[~grouped]:
        forbidden[max(0, f - burst_gap) : f + burst_gap + 1] = True
    return forbidden


def anchors(forbidden: BoolArray, first: int, last: int) -> tuple[int, int]:
    """The frame before ``first`` and the frame ``last``, moved outwards past forbidden frames.

    Parameters
    ----------
    forbidden : ndarray of bool, shape (F,)
        From :func:`forbidden_frames`.
    first, last : int
        First and last frame of a group's events (or its decay tail).

    Returns
    -------
    before, after : int
    """
    before, after = first - 1, last
    while before > 0 and forbidden[before]:
        before -= 1
    while after < len(forbidden) - 1 and forbidden[after]:
        after += 1
    return before, after


def split_unmirrored(
    frames: IntArray,
    groups: list[list[int]],
    rolls: tuple[FloatArray, FloatArray],
    naturals: tuple[FloatArray, FloatArray],
    burst_gap: int,
    mirror: float,
) -> tuple[list[list[int]], list[bool]]:
    """Groups that pair a burst with events far from it, split where the child does not mirror.

    A group whose events form two or more clusters (events within ``burst_gap``), one of them
    a burst of two or more events, holds long stretches between clusters. On each, the
    parent's and the child's levels are measured from outside: each roll continued from the
    anchor before the group with its natural velocities. A twist error moves them
    oppositely, so ``|wrap(P + C)| ≤ mirror × min(|P|, |C|)``. If a stretch fails, the group
    is split into its bursts (each then an interval of its own, or not) and its lone events
    are left unmatched.

    Parameters
    ----------
    frames : ndarray of int, shape (E,)
        Event frames, increasing.
    groups : list of list of int
        Event indices of each group, sorted.
    rolls, naturals : tuple of ndarray, each shape (F,)
        The parent's and the child's integrated roll and natural increments, radians.
    burst_gap : int
        Largest gap inside a cluster, frames.
    mirror : float
        Tolerance of the mirror, as a fraction of the smaller level.

    Returns
    -------
    groups : list of list of int
        The groups kept and the bursts of those split.
    split : list of bool
        For each group, whether it is a burst split off a group (its ends need not agree:
        the rest of its group's net was paired with it).
    """
    n_frames = len(rolls[0])
    forbidden = forbidden_frames(frames, groups, n_frames, burst_gap)
    out: list[list[int]] = []
    split: list[bool] = []
    for group in groups:
        events = frames[group]
        cuts = np.flatnonzero(np.diff(events) > burst_gap) + 1
        clusters = [list(c) for c in np.split(np.array(group), cuts)]
        if len(clusters) < 2 or max(len(c) for c in clusters) < 2:
            out.append(group)
            split.append(False)
            continue
        before, _ = anchors(forbidden, int(events[0]), int(events[-1]))
        stop = int(events[-1]) + 1
        # Continued from the anchor before the group only: the group's last event may leave
        # the roll inside the burst's error, which the child mirrors.
        parent = wrap_angle(
            rolls[0][before:stop] - rolls[0][before]
            - np.concatenate(([0.0], np.cumsum(naturals[0][before + 1 : stop])))
        )  # fmt: skip
        child = wrap_angle(
            rolls[1][before:stop] - rolls[1][before]
            - np.concatenate(([0.0], np.cumsum(naturals[1][before + 1 : stop])))
        )  # fmt: skip
        mirrored = True
        for left, right in pairwise(clusters):
            lo, hi = int(frames[left[-1]]) - before, int(frames[right[0]]) - before
            p_level = float(np.angle(np.mean(np.exp(1j * parent[lo:hi]))))
            c_level = float(np.angle(np.mean(np.exp(1j * child[lo:hi]))))
            gap = abs(float(wrap_angle(np.array(p_level + c_level))))
            mirrored &= gap <= mirror * min(abs(p_level), abs(c_level))
        if mirrored:
            out.append(group)
            split.append(False)
        else:
            bursts = [c for c in clusters if len(c) >= 2]
            out += bursts
            split += [True] * len(bursts)
    return out, split
