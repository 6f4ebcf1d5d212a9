"""Motion state of keypoints over a sliding window: speed, acceleration, jitter, confidence.

Conventions
-----------
The window is given in seconds and turned into ``max(3, round(window_s · fps))`` frames, so
the note's 5 frames at 30 fps (0.167 s) stay 0.167 s at 120 fps. Per keypoint:

* speed: mean over the window of ``|x_t − x_{t−1}| · fps`` (3D norm), unit/s;
* acceleration: mean of ``|speed_t − speed_{t−1}| · fps``, unit/s²;
* jitter: share of direction reversals, ``sign(Δx_{t+1}) ≠ sign(Δx_t)``, over the window's
  ``window − 2`` pairs, averaged over the coordinate axes, in [0, 1];
* confidence: the current sample's confidence.

The note scores each coordinate separately; one state per keypoint is used here because the
blend weights are per keypoint (the alternative, per-axis weights, lets one point's axes follow
different filters). Missing samples hold the last value, as in the note.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray

__all__ = ["MotionState", "MotionStateTracker", "window_frames"]


def window_frames(window_s: float, fps: float) -> int:
    """Number of frames of a window of ``window_s`` seconds at ``fps`` (at least 3)."""
    return max(3, round(window_s * fps))


@dataclass(frozen=True, slots=True)
class MotionState:
    """Motion state of ``K`` keypoints at one frame.

    Parameters
    ----------
    speed : ndarray, shape (K,)
        Mean speed over the window, unit/s.
    acceleration : ndarray, shape (K,)
        Mean absolute change of speed, unit/s².
    jitter : ndarray, shape (K,)
        Share of direction reversals in the window, [0, 1].
    confidence : ndarray, shape (K,)
        Current confidence, [0, 1].
    """

    speed: FloatArray
    acceleration: FloatArray
    jitter: FloatArray
    confidence: FloatArray


class MotionStateTracker:
    """Streaming motion-state detector for ``n_keypoints`` keypoints.

    Parameters
    ----------
    n_keypoints : int
        Number of keypoints.
    fps : float
        Frames per second.
    window_s : float
        Window length in seconds.
    max_frames : int, optional
        Most frames that will be given to :meth:`update` (a batch knows its take's length).
        A window longer than that keeps only ``max_frames`` rows: the rows never written hold
        zeros, which add nothing to the window's sums, so the states are the same while the
        memory follows the take, not the window.

    Notes
    -----
    Each state averages over the whole window, ``n − 1`` speeds and ``n − 2`` accelerations
    and reversals, counting the slots not written yet as 0 (the note's start-up).
    """

    def __init__(
        self, n_keypoints: int, fps: float, window_s: float, max_frames: int | None = None
    ) -> None:
        self.fps = fps
        n = window_frames(window_s, fps)
        self.n_window = n
        cap = n if max_frames is None else max(1, max_frames)
        self._held = np.full((n_keypoints, 3), np.nan)
        self._step = np.zeros((n_keypoints, 3))
        self._speed = np.zeros(n_keypoints)
        self._n_speeds, self._n_accels = n - 1, n - 2
        self._speeds = np.zeros((min(n - 1, cap), n_keypoints))
        self._accels = np.zeros((min(n - 2, cap), n_keypoints))
        self._reversals = np.zeros((min(n - 2, cap), n_keypoints))
        self._i = 0
        self._j = 0

    def update(self, positions: FloatArray, confidence: FloatArray) -> MotionState:
        """Add one frame ``(K, 3)`` with confidence ``(K,)``; return the state."""
        held = np.where(np.isnan(positions), self._held, positions)
        held = np.where(np.isnan(held), 0.0, held)
        step = held - np.where(np.isnan(self._held), held, self._held)
        speed = np.sqrt(np.einsum("kd,kd->k", step, step)) * self.fps
        reversals = np.mean(step * self._step < 0, axis=1)
        self._speeds[self._i] = speed
        self._i = (self._i + 1) % self._speeds.shape[0]
        self._accels[self._j] = np.abs(speed - self._speed) * self.fps
        self._reversals[self._j] = reversals
        self._j = (self._j + 1) % self._accels.shape[0]
        self._held = held
        self._step = step
        self._speed = speed
        # Sums over the rows kept, divided by the window's length: the mean over the window.
        return MotionState(
            speed=self._speeds.sum(axis=0) / self._n_speeds,
            acceleration=self._accels.sum(axis=0) / self._n_accels,
            jitter=self._reversals.sum(axis=0) / self._n_accels,
            confidence=np.asarray(confidence, dtype=np.float64),
        )
