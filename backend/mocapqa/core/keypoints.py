"""Keypoint sequences: per-frame 3D (or 2D) points with a confidence per point.

Conventions
-----------
* ``positions`` is ``(F, K, 3)`` float64 in file units; 2D data have ``n_dims == 2`` and a zero
  third coordinate.
* Missing values are NaN in ``positions`` and 0 in ``confidence``; they are never silently
  zero-filled. A zero-confidence detection with coordinates (OpenPose writes ``0,0,0``) is
  marked missing on read.
* ``confidence`` is ``(F, K)`` in [0, 1]; formats without one get 1.0 where a value exists.
* ``length_unit`` is recorded from the file ("m", "mm", "cm", "px", "normalized") or "unknown";
  nothing is rescaled silently.
* ``frame_numbers`` and ``times`` keep the source's own frame numbers and time column when it
  has them (a TRC's ``Frame#``/``Time``, an OpenPose folder's file numbers), so a writer can
  write them back (the TRC writer shifts the numbers to start at 1); None means frames
  ``0..F-1`` at ``frame / fps`` seconds. A copy whose frame count differs (frames sliced off)
  drops them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray, as_float_array
from mocapqa.errors import ShapeError

__all__ = ["LENGTH_UNITS", "KeypointSequence"]

LENGTH_UNITS = ("m", "cm", "mm", "in", "px", "normalized", "unknown")
"""Length units a keypoint sequence may record."""


@dataclass(frozen=True, slots=True)
class KeypointSequence:
    """Keypoints over time.

    Parameters
    ----------
    names : tuple of str
        Keypoint names, unique.
    positions : ndarray, shape (F, K, 3)
        Coordinates in ``length_unit``; NaN where missing.
    confidence : ndarray, shape (F, K)
        Detection confidence in [0, 1]; 0 where missing.
    fps : float
        Frames per second (> 0).
    length_unit : str
        One of :data:`LENGTH_UNITS`.
    n_dims : int
        2 or 3.
    source_format : str
        The format the data was read from ("trc", "openpose", ...), for display.
    assumptions : tuple of str
        What a reader had to assume because the file did not say (for example
        ``"fps 30 assumed: OpenPose JSON stores no frame rate"``); empty when nothing was assumed.
    frame_numbers : ndarray of int, shape (F,), optional
        The source's frame numbers (increasing), when it has them.
    times : ndarray, shape (F,), optional
        The source's time column, seconds, when it has one.
    start_frame : int, optional
        The source's own first-frame field, when it has one (a TRC's ``OrigDataStartFrame``).
    """

    names: tuple[str, ...]
    positions: FloatArray
    confidence: FloatArray
    fps: float
    length_unit: str = "unknown"
    n_dims: int = 3
    source_format: str = "unknown"
    assumptions: tuple[str, ...] = ()
    frame_numbers: IntArray | None = None
    times: FloatArray | None = None
    start_frame: int | None = None

    def __post_init__(self) -> None:
        k = len(self.names)
        if len(set(self.names)) != k:
            raise ShapeError("Expected unique keypoint names, got duplicates")
        positions = as_float_array(self.positions, "positions", ("F", k, 3), finite=False)
        n = positions.shape[0]
        confidence = as_float_array(self.confidence, "confidence", (n, k), finite=False)
        if np.any(np.isinf(positions)):
            raise ShapeError("Expected `positions` to be finite or NaN, got infinity")
        if np.any(~np.isfinite(confidence)) or np.any((confidence < 0) | (confidence > 1)):
            raise ShapeError("Expected `confidence` in [0, 1], got values outside")
        if not (np.isfinite(self.fps) and self.fps > 0):
            raise ShapeError(f"Expected `fps` > 0, got {self.fps}")
        if self.length_unit not in LENGTH_UNITS:
            raise ShapeError(f"Expected `length_unit` in {LENGTH_UNITS}, got {self.length_unit!r}")
        if self.n_dims not in (2, 3):
            raise ShapeError(f"Expected `n_dims` 2 or 3, got {self.n_dims}")
        missing = np.any(np.isnan(positions), axis=-1)
        confidence = np.where(missing, 0.0, confidence)
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "confidence", confidence)
        object.__setattr__(self, "fps", float(self.fps))
        # A copy with other frames (``dataclasses.replace(seq, positions=seq.positions[:40])``)
        # no longer matches the source's numbering: the numbering is dropped, not kept wrong.
        if self.frame_numbers is not None:
            numbers = np.asarray(self.frame_numbers, dtype=np.intp)
            if numbers.shape == (n,) and np.any(np.diff(numbers) <= 0):
                raise ShapeError("Expected increasing frame numbers, got a decrease or repeat")
            object.__setattr__(self, "frame_numbers", numbers if numbers.shape == (n,) else None)
        if self.times is not None:
            times = np.asarray(self.times, dtype=np.float64)
            object.__setattr__(self, "times", times if times.shape == (n,) else None)

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.positions.shape[0])

    @property
    def n_keypoints(self) -> int:
        """Number of keypoints."""
        return len(self.names)

    @property
    def missing(self) -> np.ndarray:
        """Boolean ``(F, K)``: True where a keypoint has no value."""
        mask: np.ndarray = np.any(np.isnan(self.positions), axis=-1)
        return mask

    @property
    def missing_fraction(self) -> float:
        """Share of frame × keypoint values that are missing (0 for an empty sequence)."""
        return float(self.missing.mean()) if self.positions.size else 0.0

    @property
    def duration_s(self) -> float:
        """Duration in seconds."""
        return self.n_frames / self.fps
