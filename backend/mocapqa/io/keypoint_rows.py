"""Long keypoint tables (one row per frame and keypoint) made into dense arrays.

Conventions
-----------
* A row is ``(frame, point, xyz, confidence, line)``: the frame number as written (any start),
  the keypoint's index, its coordinates in file units, its confidence and the file line it came
  from, named in errors.
* The arrays span the first to the last frame number; a (frame, keypoint) without a row is
  missing (NaN coordinates, confidence 0). A span of more than :data:`MAX_FRAME_GAP_FACTOR`
  frames per row is refused, so a stray frame number cannot claim a huge array.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import ParseError
from mocapqa.io.guards import ReadLimits, check_take_size

__all__ = ["MAX_FRAME_GAP_FACTOR", "DenseKeypoints", "KeypointRow", "dense_keypoints"]

MAX_FRAME_GAP_FACTOR = 4
"""Most frames a long table may span per row it holds."""

KeypointRow = tuple[int, int, list[float], float, int]
"""``(frame, point, xyz, confidence, line)`` of one row of a long keypoint table."""


@dataclass(frozen=True, slots=True)
class DenseKeypoints:
    """The rows of a long keypoint table as arrays.

    Attributes
    ----------
    first : int
        The first frame number.
    positions : ndarray, shape (F, K, 3)
        Coordinates, NaN where no row gives them.
    confidence : ndarray, shape (F, K)
        Confidence, 0 where no row gives it.
    """

    first: int
    positions: FloatArray
    confidence: FloatArray

    @property
    def n_frames(self) -> int:
        """F, the frames from the first to the last frame number."""
        return int(self.positions.shape[0])


def dense_keypoints(
    rows: Sequence[KeypointRow],
    n_points: int,
    path: str,
    limits: ReadLimits | None,
    repeated: Callable[[int, int], str],
) -> DenseKeypoints:
    """Place the rows of a long keypoint table in ``(F, K, 3)`` and ``(F, K)`` arrays.

    Parameters
    ----------
    rows : sequence of KeypointRow
        At least one row.
    n_points : int
        K, the keypoints the table names.
    path : str
        The file name used in messages.
    limits : ReadLimits, optional
        Refuse a take spanning more frames × keypoints than ``limits.max_frame_points``
        before its arrays are made.
    repeated : callable
        ``(frame, point) → message`` of the error on a second row of the same frame and keypoint.

    Returns
    -------
    DenseKeypoints

    Raises
    ------
    ParseError
        If the frame numbers span more than :data:`MAX_FRAME_GAP_FACTOR` frames per row, or a
        (frame, keypoint) has two rows (the second row's line).
    TooLargeError
        Beyond ``limits``.
    """
    first = min(r[0] for r in rows)
    n_frames = max(r[0] for r in rows) - first + 1
    if n_frames > MAX_FRAME_GAP_FACTOR * len(rows):
        raise ParseError(f"Expected contiguous frame numbers, got a span of {n_frames}", path)
    if limits is not None:
        check_take_size(n_frames, n_points, Path(path).name, limits)
    positions = np.full((n_frames, n_points, 3), np.nan)
    confidence = np.zeros((n_frames, n_points))
    seen = np.zeros((n_frames, n_points), dtype=bool)
    for frame, point, xyz, conf, line in rows:
        if seen[frame - first, point]:
            raise ParseError(repeated(frame, point), path, line)
        seen[frame - first, point] = True
        positions[frame - first, point] = xyz
        confidence[frame - first, point] = conf
    return DenseKeypoints(first, positions, confidence)
