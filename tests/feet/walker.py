"""Synthetic feet with known contacts: a walker and a stander, in centimetres at 120 fps.

The walker moves along +X at ``speed_cm_s`` with Y up and the feet 10 cm either side of the
path (left at +Z): each foot is planted for the first ``stance`` share of its cycle (the left
foot's cycles start at 0, the right foot's half a period later), then swings forward one
stride in a smooth step, lifted by up to 12 cm. A foot is two points, the ankle (8 cm above the
floor) and the toe (15 cm ahead, 2 cm above the floor), and the pelvis rides 90 cm above the
ankles, midway between them, so the leg length is 90 cm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.feet.points import FootPoints

FPS = 120.0
LEG_CM = 90.0
SIDES = ("left", "left", "right", "right")
PARTS = ("ankle", "toe", "ankle", "toe")
NAMES = ("LeftAnkle", "LeftToe", "RightAnkle", "RightToe")
_OFFSETS = np.array([[0.0, 8.0, 0.0], [15.0, 2.0, 0.0]])  # ankle, toe from the foot origin


@dataclass(frozen=True)
class Walk:
    """Positions of a synthetic walk and the frames of each planted phase."""

    points: FootPoints
    stances: dict[str, list[tuple[int, int]]]


def _smoothstep(u: FloatArray) -> FloatArray:
    out: FloatArray = u * u * (3.0 - 2.0 * u)
    return out


def walk(
    seconds: float = 6.0, period_s: float = 1.1, stance: float = 0.62, speed_cm_s: float = 120.0
) -> Walk:
    """A straight walk with Y up (see the module notes)."""
    n = round(seconds * FPS)
    t = np.arange(n) / FPS
    stride = speed_cm_s * period_s
    positions = np.zeros((n, 4, 3))
    stances: dict[str, list[tuple[int, int]]] = {}
    for k, (side, lateral, phase) in enumerate((("left", 10.0, 0.0), ("right", -10.0, 0.5))):
        cycle = (t / period_s - phase) + 1.0  # +1: every frame in a cycle ≥ 0
        index = np.floor(cycle)
        u = cycle - index
        swing = np.clip((u - stance) / (1.0 - stance), 0.0, 1.0)
        x = (index + _smoothstep(swing)) * stride - phase * stride
        lift = 12.0 * np.sin(np.pi * swing)
        for j in range(2):
            positions[:, 2 * k + j, 0] = x + _OFFSETS[j, 0]
            positions[:, 2 * k + j, 1] = lift + _OFFSETS[j, 1]
            positions[:, 2 * k + j, 2] = lateral
        planted = u < stance
        edges = np.diff(np.concatenate(([0], planted.astype(int), [0])))
        starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
        stances[side] = [(int(a), int(b)) for a, b in zip(starts, stops, strict=True)]
    ankles_x = positions[:, [0, 2], 0].mean(axis=1)
    pelvis = np.stack([ankles_x, np.full(n, 98.0), np.zeros(n)], axis=1)
    return Walk(_points(positions, pelvis), stances)


def stand(seconds: float = 4.0) -> FootPoints:
    """Both feet planted the whole time, Y up."""
    n = round(seconds * FPS)
    positions = np.zeros((n, 4, 3))
    for k, lateral in enumerate((10.0, -10.0)):
        for j in range(2):
            positions[:, 2 * k + j] = _OFFSETS[j] + [0.0, 0.0, lateral]
    pelvis = np.tile([0.0, 98.0, 0.0], (n, 1))
    return _points(positions, pelvis)


def _points(positions: FloatArray, pelvis: FloatArray) -> FootPoints:
    return FootPoints(
        positions=positions, sides=SIDES, parts=PARTS, names=NAMES, fps=FPS,
        leg_length=LEG_CM, length_unit="cm", pelvis=pelvis,
    )  # fmt: skip


def reaxed(points: FootPoints, order: tuple[int, int, int], signs: tuple[float, ...]) -> FootPoints:
    """The same take with its axes permuted (``new[..., i] = signs[i] * old[..., order[i]]``)."""
    from dataclasses import replace

    sign = np.asarray(signs)
    pelvis = None if points.pelvis is None else points.pelvis[:, list(order)] * sign
    return replace(points, positions=points.positions[..., list(order)] * sign, pelvis=pelvis)
