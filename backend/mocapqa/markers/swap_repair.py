"""Which swaps a repair applies, and the repair: the two labels' samples exchanged over each
swap's interval (frames 0-based, ends inclusive)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError, OptionError
from mocapqa.markers.params import MarkerParams
from mocapqa.markers.swaps import Swap

__all__ = ["APPLY_RULES", "repair_swaps", "select_swaps", "swapped_mask"]

APPLY_RULES = ("confident", "all", "none")
"""Which swaps a repair applies: those at or above ``swap_confidence``, all, or none."""


def select_swaps(
    swaps: Sequence[Swap],
    apply: Literal["confident", "all", "none"] | str,
    params: MarkerParams | None = None,
) -> list[Swap]:
    """The swaps a repair applies under ``apply`` (:data:`APPLY_RULES`).

    Raises
    ------
    OptionError
        If ``apply`` is not one of :data:`APPLY_RULES`.
    """
    p = params or MarkerParams()
    if apply not in APPLY_RULES:
        raise OptionError("apply", f"Expected one of {', '.join(APPLY_RULES)}, got {apply!r}")
    if apply == "none":
        return []
    if apply == "all":
        return list(swaps)
    return [s for s in swaps if s.confidence >= p.swap_confidence]


def repair_swaps(samples: FloatArray, swaps: Sequence[Swap]) -> FloatArray:
    """A copy of ``samples`` with each swap's two labels exchanged over its interval.

    Parameters
    ----------
    samples : ndarray, shape (F, M, ...)
        Positions ``(F, M, 3)``, residuals ``(F, M)`` or any per-sample array.
    swaps : sequence of Swap
        Applied in order; they should not share a marker over overlapping frames.

    Returns
    -------
    ndarray
        Same shape and dtype; ``samples`` is not modified.

    Raises
    ------
    InputError
        If a swap lies outside the take.
    """
    out = np.array(samples, copy=True)
    n_frames, n_markers = out.shape[:2]
    for swap in swaps:
        a, b = swap.indices
        if not (0 <= swap.start <= swap.end < n_frames and 0 <= a < n_markers
                and 0 <= b < n_markers):  # fmt: skip
            raise InputError(
                f"Expected a swap inside {n_frames} frames and {n_markers} markers, got "
                f"markers {a}, {b} over frames {swap.start}–{swap.end}"
            )
        window = slice(swap.start, swap.end + 1)
        out[window, [a, b]] = out[window, [b, a]]
    return out


def swapped_mask(shape: tuple[int, int], swaps: Sequence[Swap]) -> BoolArray:
    """``(F, M)`` mask of the samples the swaps exchange."""
    mask = np.zeros(shape, dtype=bool)
    for swap in swaps:
        mask[swap.start : swap.end + 1, list(swap.indices)] = True
    return mask
