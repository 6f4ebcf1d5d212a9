"""Circular twist intervals of the lookup map's bins: shortest arcs, smoothing, dilation.

A bin's twist interval is held as a centre and a half-width (radians): the twists
``wrap(τ − centre) ∈ [−half, half]``. Built from samples it is the shortest arc covering them
(the complement of the largest gap between them), so samples straddling ±180° give a short arc
across it, never "everything but the arc". Smoothing and dilation work on centres (the short
way round) and half-widths. See :mod:`mocapqa.limits.occupancy` for the map they form.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray

__all__ = ["circular_intervals", "dilate", "smooth", "wrap"]

_KERNEL = np.outer([1.0, 2.0, 1.0], [1.0, 2.0, 1.0]) / 16.0


def wrap(angles: FloatArray) -> FloatArray:
    """Angles wrapped to ``[−π, π)``."""
    return np.asarray((angles + np.pi) % (2.0 * np.pi) - np.pi, dtype=np.float64)


def circular_intervals(
    flat: IntArray, tau: FloatArray, n: int
) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Per bin, the shortest arc covering its twists.

    Parameters
    ----------
    flat : ndarray of int, shape (S,)
        Flat bin index ``i1 * n + i2`` of every sample.
    tau : ndarray, shape (S,)
        Twist of every sample, radians.
    n : int
        Bins per swing axis.

    Returns
    -------
    centre, half : ndarray, shape (n, n)
        Radians, NaN on empty bins.
    occupied : ndarray of bool, shape (n, n)
    """
    centre = np.full(n * n, np.nan)
    half = np.full(n * n, np.nan)
    wrapped = wrap(tau)  # sorted after wrapping: a twist of exactly π (or beyond) wraps to −π
    order = np.lexsort((wrapped, flat))
    flat_s, tau_s = flat[order], wrapped[order]
    starts = np.flatnonzero(np.r_[True, flat_s[1:] != flat_s[:-1]])
    ends = np.r_[starts[1:], flat_s.size]
    for a, b in zip(starts, ends, strict=True):
        values = tau_s[a:b]
        gaps = np.diff(np.r_[values, values[0] + 2.0 * np.pi])
        k = int(np.argmax(gaps))
        low = values[(k + 1) % values.size]
        width = 2.0 * np.pi - gaps[k]
        centre[flat_s[a]] = wrap(np.asarray(low + 0.5 * width))
        half[flat_s[a]] = 0.5 * width
    occupied = np.isfinite(centre).reshape(n, n)
    return centre.reshape(n, n), half.reshape(n, n), occupied


def _neighbours(values: FloatArray) -> list[tuple[float, FloatArray]]:
    """The 3×3 neighbourhood of every bin, zero-padded: (kernel weight, neighbour values)."""
    n = values.shape[0]
    padded = np.pad(values, 1)
    return [
        (float(_KERNEL[d1 + 1, d2 + 1]), padded[1 + d1 : 1 + d1 + n, 1 + d2 : 1 + d2 + n])
        for d1 in (-1, 0, 1)
        for d2 in (-1, 0, 1)
    ]


def _neighbourhood(
    occupied: BoolArray, centre: FloatArray, half: FloatArray
) -> tuple[FloatArray, list[tuple[float, FloatArray, FloatArray, FloatArray]]]:
    """Every bin's own centre (0 where empty) and its 3×3 neighbours' (kernel weight, occupied
    as 0/1, centre, half-width), centre and half-width 0 where empty."""
    own = np.where(occupied, centre, 0.0)
    triples = zip(
        _neighbours(occupied.astype(np.float64)),
        _neighbours(own),
        _neighbours(np.where(occupied, half, 0.0)),
        strict=True,
    )
    return own, [(w, o, c, h) for (w, o), (_, c), (_, h) in triples]


def smooth(
    centre: FloatArray, half: FloatArray, occupied: BoolArray
) -> tuple[FloatArray, FloatArray]:
    """3×3 Gaussian smoothing over occupied bins of the centres and the half-widths.

    Returns
    -------
    centre, half : ndarray, shape (n, n)
        NaN on empty bins.
    """
    own, around = _neighbourhood(occupied, centre, half)
    total_c = np.zeros_like(own)
    total_h = np.zeros_like(own)
    norm = np.zeros_like(own)
    for w, o, c, h in around:
        total_c += w * o * wrap(c - own)
        total_h += w * o * h
        norm += w * o
    norm = np.where(norm > 0, norm, 1.0)
    return (
        np.where(occupied, wrap(own + total_c / norm), np.nan),
        np.where(occupied, total_h / norm, np.nan),
    )


def dilate(
    occupied: BoolArray, centre: FloatArray, half: FloatArray
) -> tuple[BoolArray, FloatArray, FloatArray]:
    """Add one ring of bins, each with the union (widest arc) of its occupied neighbours.

    The neighbours' arcs are unrolled around the circular mean of their centres before the
    union is taken.
    """
    ring = ndimage.binary_dilation(occupied, structure=np.ones((3, 3), bool)) & ~occupied
    _, around = _neighbourhood(occupied, centre, half)
    # Centres as unit vectors: their sum's direction is the neighbours' circular mean.
    sin_sum = sum(o * np.sin(c) for _, o, c, _ in around)
    cos_sum = sum(o * np.cos(c) for _, o, c, _ in around)
    reference = np.arctan2(sin_sum, cos_sum)
    low = np.full(occupied.shape, np.inf)
    high = np.full(occupied.shape, -np.inf)
    for _, o, c, h in around:
        mid = reference + wrap(c - reference)
        low = np.where(o > 0, np.minimum(low, mid - h), low)
        high = np.where(o > 0, np.maximum(high, mid + h), high)
    high = np.where(ring, high, 0.0)
    low = np.where(ring, low, 0.0)
    return (
        occupied | ring,
        np.where(ring, wrap(0.5 * (high + low)), centre),
        np.where(ring, np.minimum(0.5 * (high - low), np.pi), half),
    )
