"""Seeded vision-like noise for filter benchmarks.

Conventions
-----------
Keypoints (lengths given in mm and converted with ``units_per_mm``): per-axis Gaussian jitter
whose σ drifts slowly between 5 and 20 mm (one sinusoid of 0.05–0.3 Hz per keypoint), 30 %
frame-to-frame correlation (AR(1) with coefficient 0.3, unit variance), confidence
``1 / (1 + (σ / 15 mm)²)``; outliers of 50–200 mm in a random direction at 0.15 per second per
keypoint with confidence 0.05–0.4; dropouts of 0.1–0.33 s at 0.06 per second per keypoint that
hold the last value with confidence 0. Rotations: per-joint white noise of 2–10° RMS angle,
single-frame spikes of 20–60° at 0.15 per second, and a random quaternion sign per frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.kinematics.quaternion import exp_map, multiply

__all__ = ["NoisyKeypoints", "keypoint_noise", "rotation_noise"]


@dataclass(frozen=True, slots=True)
class NoisyKeypoints:
    """Noisy keypoints with their confidence and event masks.

    Parameters
    ----------
    positions : ndarray, shape (F, K, 3)
    confidence : ndarray, shape (F, K)
    outliers : ndarray of bool, shape (F, K)
    dropouts : ndarray of bool, shape (F, K)
    """

    positions: FloatArray
    confidence: FloatArray
    outliers: BoolArray
    dropouts: BoolArray


def _random_directions(rng: np.random.Generator, n: int) -> FloatArray:
    d = rng.normal(size=(n, 3))
    return np.asarray(d / np.linalg.norm(d, axis=1, keepdims=True))


def keypoint_noise(
    truth: FloatArray, fps: float, rng: np.random.Generator, units_per_mm: float
) -> NoisyKeypoints:
    """Add the benchmark's keypoint noise to ``truth`` ``(F, K, 3)``; see the module docstring."""
    n, k, _ = truth.shape
    t = np.arange(n) / fps
    freq = rng.uniform(0.05, 0.3, size=k)
    phase = rng.uniform(0, 2 * np.pi, size=k)
    sigma_mm = 12.5 + 7.5 * np.sin(2 * np.pi * freq * t[:, None] + phase)
    confidence = 1.0 / (1.0 + (sigma_mm / 15.0) ** 2)
    white = rng.normal(size=(n, k, 3))
    ar = np.empty_like(white)
    ar[0] = white[0]
    rho = 0.3
    for i in range(1, n):
        ar[i] = rho * ar[i - 1] + np.sqrt(1 - rho * rho) * white[i]
    noisy = truth + ar * (sigma_mm * units_per_mm)[:, :, None]
    outliers = rng.random((n, k)) < 0.15 / fps
    count = int(outliers.sum())
    size = rng.uniform(50, 200, size=count) * units_per_mm
    noisy[outliers] += _random_directions(rng, count) * size[:, None]
    confidence[outliers] = rng.uniform(0.05, 0.4, size=count)
    dropouts = np.zeros((n, k), dtype=bool)
    starts = np.argwhere(rng.random((n, k)) < 0.06 / fps)
    for frame, key in starts:
        length = max(1, round(rng.uniform(0.1, 0.33) * fps))
        dropouts[frame : frame + length, key] = True
    for frame, key in np.argwhere(dropouts):
        if frame > 0:
            noisy[frame, key] = noisy[frame - 1, key]
    confidence[dropouts] = 0.0
    return NoisyKeypoints(noisy, confidence, outliers & ~dropouts, dropouts)


def rotation_noise(quats: FloatArray, fps: float, rng: np.random.Generator) -> FloatArray:
    """Add the benchmark's rotation noise to ``(F, J, 4)`` quats; see the module docstring."""
    n, j, _ = quats.shape
    rms = np.radians(rng.uniform(2, 10, size=j))
    rotvec = rng.normal(size=(n, j, 3)) * (rms / np.sqrt(3))[None, :, None]
    spikes = rng.random((n, j)) < 0.15 / fps
    count = int(spikes.sum())
    rotvec[spikes] = (
        _random_directions(rng, count) * np.radians(rng.uniform(20, 60, count))[:, None]
    )
    noisy = multiply(exp_map(rotvec), quats)
    return np.asarray(noisy * np.where(rng.random((n, j, 1)) < 0.5, -1.0, 1.0))
