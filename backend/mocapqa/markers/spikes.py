"""Spikes: accelerations far outside a marker's own motion, for a few frames at most.

Conventions
-----------
* A marker's acceleration is its second difference times fps² (take units per s²). Its
  **departure** at frame t is the acceleration minus the mean of its two neighbours',
  ``a(t) − (a(t−1) + a(t+1)) / 2`` (a fourth difference: ``−Δ⁴x · fps² / 2``): smooth motion,
  however fast, changes its acceleration little from one frame to the next, while a sample
  off its path by ``e`` departs by ``3 e · fps²`` at that frame and ``2 e · fps²`` at its
  neighbours.
* Per marker, the length of the departure is compared with its own robust level: the median
  plus ``spike_ratio`` robust spreads (1.4826 × MAD) over the marker's frames, and with the
  departure ``3 · spike_min_offset · fps²`` of one sample ``spike_min_offset`` mm off its path
  (in take units); frames above both are flagged. Each spike also gives that off-path
  distance, ``offset = size / (3 fps²)``.
* Flagged frames at most 2 apart join one run; a run of at most ``spike_max_frames`` frames is
  a spike (a longer one is a jump that persists or a burst of noise, reported by the swap and
  gap checks rather than as a spike). Where the marker has rigid mates, its misfit against them
  must rise by ``spike_misfit`` in the run (a glitch moves one marker off its segment, fast
  motion moves the segment). Runs next to a swap's first or last frame of the same
  marker are the swap's own jumps and are left out by the caller.
* A frame needs its two neighbours on each side (five frames) to be measured; others are not.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray, column_runs
from mocapqa.markers.params import MarkerParams, unit_scale
from mocapqa.markers.take import close_breaks

__all__ = ["Spike", "departures", "find_spikes"]

_MAD_TO_SIGMA = 1.4826
"""Robust spread of a normal variable per unit of median absolute deviation."""


@dataclass(frozen=True, slots=True)
class Spike:
    """A few frames where a marker leaves its path.

    Parameters
    ----------
    marker : str
    index : int
        The marker's index.
    start, end : int
        First and last flagged frame, 0-based, inclusive.
    peak : int
        Frame of the largest departure.
    size : float
        The largest departure, take units per s².
    offset : float
        ``size / (3 fps²)``: how far off its path a single sample would be, take units.
    ratio : float
        ``size`` over the marker's flagging threshold (≥ 1).
    severity : {"warning", "error"}
        Error at 3 × the threshold and above.
    """

    marker: str
    index: int
    start: int
    end: int
    peak: int
    size: float
    offset: float
    ratio: float
    severity: str


def departures(positions: FloatArray, fps: float) -> FloatArray:
    """Length of each sample's acceleration departure, ``(F, M)``, take units per s².

    NaN at the first and last two frames and wherever one of the five samples is missing.
    """
    n_frames, n_markers = positions.shape[:2]
    out = np.full((n_frames, n_markers), np.nan)
    if n_frames >= 5:
        p = positions
        fourth = p[:-4] - 4.0 * p[1:-3] + 6.0 * p[2:-2] - 4.0 * p[3:-1] + p[4:]
        out[2:-2] = np.sqrt(np.einsum("fmk,fmk->fm", fourth, fourth)) * (0.5 * fps * fps)
    return out


def _breaks_segment(misfit: FloatArray, start: int, end: int, rise: float) -> bool:
    """Whether a marker's misfit ``(F,)`` rises by ``rise`` over ``start..end`` above its
    level on the 3 frames either side (True when it cannot be measured there)."""
    inside = misfit[start : end + 1]
    around = np.concatenate([misfit[max(start - 3, 0) : start], misfit[end + 1 : end + 4]])
    around = around[np.isfinite(around)]
    if not np.isfinite(inside).any() or around.size == 0:
        return True
    return bool(np.nanmax(inside) - np.median(around) >= rise)


def find_spikes(
    positions: FloatArray,
    names: Sequence[str],
    fps: float,
    length_unit: str,
    params: MarkerParams | None = None,
    misfit: FloatArray | None = None,
) -> list[Spike]:
    """Spikes of every marker.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    names : sequence of str
    fps : float
    length_unit : str
    params : MarkerParams, optional
    misfit : ndarray, shape (F, M), optional
        Each marker's misfit against its rigid mates (:func:`mocapqa.markers.misfits.misfits`,
        tolerances; NaN where unknown). When given, a run of a marker measured there is a
        spike only if its misfit rises by ``spike_misfit`` in it above its level on the 3
        frames either side: a marker that leaves its path also leaves its segment, while a
        fast limb moves its markers together.

    Returns
    -------
    list of Spike
        By marker, then start frame.
    """
    p = params or MarkerParams()
    size = departures(positions, fps)
    measured = np.isfinite(size)
    if not measured.any():
        return []
    with np.errstate(invalid="ignore"):
        level = np.nanmedian(np.where(measured.any(axis=0), size, 0.0), axis=0)
        spread = _MAD_TO_SIGMA * np.nanmedian(
            np.abs(np.where(measured.any(axis=0), size, 0.0) - level), axis=0
        )
        threshold = np.maximum(
            level + p.spike_ratio * spread,
            3.0 * fps * fps * p.spike_min_offset * unit_scale(length_unit),
        )
        flagged = size > threshold
    joined = close_breaks(flagged, 2)
    markers, starts, ends = column_runs(joined)
    spikes: list[Spike] = []
    for m, start, end in zip(markers, starts, ends, strict=True):
        if end - start + 1 > p.spike_max_frames:
            continue
        if misfit is not None and not _breaks_segment(misfit[:, m], start, end, p.spike_misfit):
            continue
        window = size[start : end + 1, m]
        offset = int(np.nanargmax(window))
        peak = float(window[offset])
        ratio = peak / float(threshold[m])
        spikes.append(
            Spike(
                names[int(m)],
                int(m),
                int(start),
                int(end),
                int(start + offset),
                peak,
                peak / (3.0 * fps * fps),
                ratio,
                "error" if ratio >= 3.0 else "warning",
            )
        )
    return spikes
