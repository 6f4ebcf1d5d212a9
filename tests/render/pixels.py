"""Pixel checks shared by the render tests, and the known error injected into the kick take."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["BROKEN_FRAMES", "BROKEN_JOINT", "bounding_box", "content_mask", "red_mask"]

BROKEN_JOINT = "UpperArm_R"
BROKEN_FRAMES = (40, 70)


def content_mask(image: NDArray[np.uint8]) -> NDArray[np.bool_]:
    """Pixels of the skeleton: dark or saturated, unlike the white background and grey floor."""
    rgb = image.astype(np.int16)
    dark = rgb.max(axis=-1) < 150
    saturated = (rgb.max(axis=-1) - rgb.min(axis=-1)) > 80
    mask: NDArray[np.bool_] = dark | saturated
    return mask


def red_mask(image: NDArray[np.uint8]) -> NDArray[np.bool_]:
    """Pixels of the flagged colour (#d62728 and its shading)."""
    rgb = image.astype(np.int16)
    return (rgb[..., 0] > 150) & (rgb[..., 1] < 90) & (rgb[..., 2] < 90)


def bounding_box(mask: NDArray[np.bool_]) -> tuple[int, int, int, int]:
    """(top, bottom, left, right) of the True pixels."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    return int(rows[0]), int(rows[-1]), int(cols[0]), int(cols[-1])
