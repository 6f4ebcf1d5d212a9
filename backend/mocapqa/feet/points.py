"""Foot points: the one input of the feet checks, whatever kind of take they came from.

Conventions
-----------
* ``positions`` is ``(F, P, 3)`` float64, world coordinates in the take's length unit, NaN where
  a keypoint is missing. BVH takes give joint positions from forward kinematics, keypoint takes
  their ankle, heel and toe keypoints (``mocapqa.pipeline.feet`` builds both).
* Each point has a side (``"left"``, ``"right"``) and a part: ``"heel"`` (a heel keypoint),
  ``"ankle"`` (the ankle joint or keypoint, standing in for the heel where there is none) or
  ``"toe"`` (toe joint, big toe, MediaPipe's foot index). Each foot has one or two points: a
  rear one (heel or ankle), then a toe where the take has one; the skate check reads the
  foot as the line between them.
* ``leg_length`` (hip → knee → ankle, take units) is the length scale of every threshold, so the
  checks need no unit and suit any body size; ``length_unit`` only converts the sizes reported.
* ``pelvis`` ``(F, 3)``, when given, is a body point above the feet (the hip joints' midpoint):
  the gravity-free cue of the up axis.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from mocapqa.core.arrays import FloatArray, as_float_array
from mocapqa.core.rig_names import Side
from mocapqa.errors import ShapeError

__all__ = [
    "CM_PER_UNIT",
    "LEG_HEIGHT_RATIO",
    "PARTS",
    "SIDES",
    "FootPoints",
    "cm_per_unit",
    "per_foot",
]

SIDES: tuple[Side, ...] = ("left", "right")
"""The feet, in the order they are listed."""
PARTS = ("heel", "ankle", "toe")
"""Foot parts a point can stand for."""
CM_PER_UNIT = {"m": 100.0, "cm": 1.0, "mm": 0.1, "in": 2.54}
"""Centimetres per length unit, for the units that convert exactly."""
LEG_HEIGHT_RATIO = 0.491
"""Leg length (hip joint → knee → ankle) over body height: thigh 0.245 H plus shank 0.246 H
(Winter, *Biomechanics and Motor Control of Human Movement*, 4th ed., 2009, fig. 4.1). Turns a
leg length into the body height that sizes in unknown units are reported against."""


def cm_per_unit(length_unit: str) -> float | None:
    """Centimetres per unit of ``length_unit``, or None for px, normalized and unknown."""
    return CM_PER_UNIT.get(length_unit)


@dataclass(frozen=True, slots=True)
class FootPoints:
    """World positions of foot points over a take.

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
        Take units; NaN where missing.
    sides : tuple of str
        ``"left"`` or ``"right"`` per point.
    parts : tuple of str
        One of :data:`PARTS` per point.
    names : tuple of str
        The joint or keypoint each point is, for display.
    fps : float
        Frames per second (> 0).
    leg_length : float
        Hip → knee → ankle length, take units (> 0).
    length_unit : str
        The take's length unit ("cm", "m", "mm", "in", "px", "normalized", "unknown").
    pelvis : ndarray, shape (F, 3), optional
        A body point above the feet (midpoint of the hips), take units.
    confidence : ndarray, shape (F, P), optional
        Detection confidence in [0, 1] per point (keypoint takes).
    """

    positions: FloatArray
    sides: tuple[str, ...]
    parts: tuple[str, ...]
    names: tuple[str, ...]
    fps: float
    leg_length: float
    length_unit: str = "unknown"
    pelvis: FloatArray | None = None
    confidence: FloatArray | None = None

    def __post_init__(self) -> None:
        n_points = len(self.names)
        positions = as_float_array(self.positions, "positions", ("F", n_points, 3), finite=False)
        if np.any(np.isinf(positions)):
            raise ShapeError("Expected `positions` to be finite or NaN, got infinity")
        if len(self.sides) != n_points or len(self.parts) != n_points:
            raise ShapeError(
                f"Expected a side and a part for each of {n_points} points, got "
                f"{len(self.sides)} sides and {len(self.parts)} parts"
            )
        if bad := [s for s in self.sides if s not in SIDES]:
            raise ShapeError(f"Expected sides in {SIDES}, got {bad[0]!r}")
        if bad := [p for p in self.parts if p not in PARTS]:
            raise ShapeError(f"Expected parts in {PARTS}, got {bad[0]!r}")
        for side in SIDES:
            parts = [q for s, q in zip(self.sides, self.parts, strict=True) if s == side]
            if not 1 <= len(parts) <= 2 or parts.count("toe") > 1 or parts[0] == "toe" != parts[-1]:
                raise ShapeError(
                    f"Expected one or two points on the {side} foot (heel or ankle, then toe), "
                    f"got {parts}"
                )
        if not (np.isfinite(self.fps) and self.fps > 0):
            raise ShapeError(f"Expected `fps` > 0, got {self.fps}")
        if not (np.isfinite(self.leg_length) and self.leg_length > 0):
            raise ShapeError(f"Expected `leg_length` > 0, got {self.leg_length}")
        n_frames = positions.shape[0]
        if self.pelvis is not None:
            pelvis = as_float_array(self.pelvis, "pelvis", (n_frames, 3), finite=False)
            object.__setattr__(self, "pelvis", pelvis)
        if self.confidence is not None:
            confidence = as_float_array(
                self.confidence, "confidence", (n_frames, n_points), finite=False
            )
            object.__setattr__(self, "confidence", confidence)
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "fps", float(self.fps))
        object.__setattr__(self, "leg_length", float(self.leg_length))

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.positions.shape[0])

    @property
    def n_points(self) -> int:
        """Number of foot points."""
        return len(self.names)

    @property
    def body_height(self) -> float:
        """Body height estimated from the leg length (:data:`LEG_HEIGHT_RATIO`), take units."""
        return self.leg_length / LEG_HEIGHT_RATIO

    def side_indices(self, side: str) -> list[int]:
        """Indices of the points of one foot."""
        return [p for p, s in enumerate(self.sides) if s == side]


def per_foot(values: NDArray[Any], sides: tuple[str, ...], ufunc: np.ufunc) -> NDArray[Any]:
    """Reduce ``values`` ``(F, P)`` over each foot's points with ``ufunc`` (``np.maximum``,
    ``np.minimum``, ``np.logical_or``, ``np.add``).

    Returns
    -------
    ndarray, shape (F, 2)
        Left foot, then right (each foot has at least one point, see :class:`FootPoints`).
    """
    array = np.asarray(values)
    columns = [
        ufunc.reduce(array[:, [p for p, s in enumerate(sides) if s == side]], axis=1)
        for side in SIDES
    ]
    return np.stack(columns, axis=1)
