"""Repetition evidence: twist errors come in families on one chain of one take.

A retarget or a solve that breaks a joint's roll breaks it again and again: the same knee of
the same take flips many times (``005_05``'s right calf: five separate intervals in two
seconds). :func:`family_counts` counts, for each interval, the *other* strong intervals on its
chain in the take, those the default choice applies on evidence of their own (a calibrated
probability of at least ``strong`` or the anatomy rule). It reads nothing of the interval
itself, so an interval cannot support itself, and a take with no strong interval gives no
support to any.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import BoolArray, IntArray

__all__ = ["family_counts"]


def family_counts(chains: IntArray, strong: BoolArray) -> IntArray:
    """Other strong intervals on each interval's chain.

    Parameters
    ----------
    chains : ndarray of int, shape (N,)
        Chain index of each interval of a take.
    strong : ndarray of bool, shape (N,)
        Whether each interval is strong (applied on its own evidence).

    Returns
    -------
    ndarray of int, shape (N,)
        Strong intervals on the same chain, the interval itself not counted.
    """
    chains = np.asarray(chains, dtype=np.intp)
    strong = np.asarray(strong, dtype=bool)
    if chains.size == 0:
        return np.zeros(0, dtype=np.intp)
    per_chain = np.bincount(chains, weights=strong.astype(np.float64))
    result: IntArray = (per_chain[chains] - strong).astype(np.intp)
    return result
