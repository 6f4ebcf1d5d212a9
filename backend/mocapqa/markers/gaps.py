"""Per-marker gaps: every run of missing samples, and each marker's count, longest and share.

A gap is a run of frames where a marker is missing (any coordinate not finite). Gaps at the
start or the end of the take are listed like the others and flagged ``edge``: a fill has data
on one side only. Severity grows with length: ``info`` below ``gap_warning_s``, ``warning``
below ``gap_error_s``, ``error`` from there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, column_runs
from mocapqa.markers.params import MarkerParams

__all__ = ["Gap", "MarkerGaps", "find_gaps", "gap_severity", "summarise_gaps"]


@dataclass(frozen=True, slots=True)
class Gap:
    """One run of missing samples of one marker.

    Parameters
    ----------
    marker : str
    start, end : int
        First and last missing frame, 0-based, inclusive.
    frames : int
        ``end - start + 1``.
    seconds : float
        ``frames / fps``.
    edge : bool
        Whether the gap touches the first or the last frame.
    severity : {"info", "warning", "error"}
    """

    marker: str
    start: int
    end: int
    frames: int
    seconds: float
    edge: bool
    severity: str


@dataclass(frozen=True, slots=True)
class MarkerGaps:
    """The gap summary of one marker.

    Parameters
    ----------
    marker : str
    count : int
        Number of gaps.
    longest : int
        Longest gap, frames (0 without gaps).
    longest_s : float
        Longest gap, seconds.
    missing : float
        Share of the take's frames where the marker is missing (0–1).
    """

    marker: str
    count: int
    longest: int
    longest_s: float
    missing: float


def gap_severity(seconds: float, params: MarkerParams) -> str:
    """``info``, ``warning`` or ``error`` for a gap of ``seconds``."""
    if seconds >= params.gap_error_s:
        return "error"
    return "warning" if seconds >= params.gap_warning_s else "info"


def find_gaps(
    present: BoolArray, names: Sequence[str], fps: float, params: MarkerParams | None = None
) -> list[Gap]:
    """Every gap of every marker.

    Parameters
    ----------
    present : ndarray of bool, shape (F, M)
        Where each marker is visible.
    names : sequence of str
        The M marker labels.
    fps : float
        Frames per second.
    params : MarkerParams, optional

    Returns
    -------
    list of Gap
        By marker (in ``names`` order), then start frame.
    """
    p = params or MarkerParams()
    markers, starts, ends = column_runs(~present)
    last = present.shape[0] - 1
    lengths = ends - starts + 1
    return [
        Gap(
            names[int(m)], int(s), int(e), int(n), float(n / fps), bool(s == 0 or e == last),
            gap_severity(float(n / fps), p),
        )
        for m, s, e, n in zip(markers, starts, ends, lengths, strict=True)
    ]  # fmt: skip


def summarise_gaps(present: BoolArray, names: Sequence[str], fps: float) -> list[MarkerGaps]:
    """Count, longest gap and share missing of every marker, in ``names`` order.

    Parameters
    ----------
    present : ndarray of bool, shape (F, M)
    names : sequence of str
    fps : float

    Returns
    -------
    list of MarkerGaps
    """
    n_frames, n_markers = present.shape
    markers, starts, ends = column_runs(~present)
    counts = np.bincount(markers, minlength=n_markers)
    longest = np.zeros(n_markers, dtype=np.intp)
    np.maximum.at(longest, markers, ends - starts + 1)
    missing = 1.0 - present.mean(axis=0) if n_frames else np.zeros(n_markers)
    return [
        MarkerGaps(names[m], int(counts[m]), int(longest[m]), float(longest[m] / fps),
                   float(missing[m]))
        for m in range(n_markers)
    ]  # fmt: skip
