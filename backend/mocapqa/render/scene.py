"""What to draw: a skeleton track (points over time plus a bone list), its up axis and camera.

Conventions
-----------
* A :class:`SkeletonTrack` holds world positions ``(F, J, 3)`` in file units (NaN where a
  keypoint is missing) and bones as ``(B, 2)`` index pairs, parent first. Zero-length bones
  (CMU's ``LHipJoint``, iClone's ``*ShareBone``) are dropped when the track is built.
* The up axis is one signed world axis ("+y", "-y", "+z", ...). It is taken from the mean
  head-minus-feet vector when joint names say which is which (so MediaPipe's y-down world gives
  "-y" and pybvh's Z-up example "+z"), else from the axis of largest per-frame extent; callers
  may override it. The alternative, always assuming Y-up, draws Z-up and y-down rigs lying
  down or upside down.
* The camera looks at the centre of the bounding box of the chosen frames from a fixed
  three-quarter direction above the floor, far enough that the whole box fits the view.

Everything here is numpy only; pyvista is imported by :mod:`mocapqa.render.engine`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray, as_float_array
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ShapeError
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.render.layouts import bones_for_keypoints

__all__ = [
    "UP_AXES",
    "CameraView",
    "SkeletonTrack",
    "bones_from_parents",
    "check_same_shape",
    "detect_up_axis",
    "frame_camera",
    "track_from_keypoints",
    "track_from_motion",
    "track_from_points",
    "up_vector",
]

# Signed world axes a take can have as "up".
UP_AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
_HEAD_WORDS = ("head", "nose", "neck", "eye", "ear")
_FOOT_WORDS = ("foot", "toe", "ankle", "heel")
_VIEW_ANGLE_DEG = 30.0


def up_vector(up_axis: str) -> FloatArray:
    """Unit vector ``(3,)`` of a signed axis name such as ``"-y"``.

    Raises
    ------
    ShapeError
        If ``up_axis`` is not one of :data:`UP_AXES`.
    """
    if up_axis not in UP_AXES:
        raise ShapeError(f"Expected `up_axis` in {UP_AXES}, got {up_axis!r}")
    vector = np.zeros(3)
    vector["xyz".index(up_axis[1])] = 1.0 if up_axis[0] == "+" else -1.0
    return vector


def _name_mask(names: tuple[str, ...], words: tuple[str, ...]) -> BoolArray:
    lowered = [n.lower() for n in names]
    return np.array([any(w in n for w in words) for n in lowered], dtype=bool)


def detect_up_axis(positions: FloatArray, names: tuple[str, ...]) -> str:
    """Guess the signed up axis of a take.

    Parameters
    ----------
    positions : ndarray, shape (F, J, 3)
        World positions, file units; NaN allowed.
    names : tuple of str
        Joint or keypoint names, length J.

    Returns
    -------
    str
        One of :data:`UP_AXES`.
    """
    heads = _name_mask(names, _HEAD_WORDS)
    feet = _name_mask(names, _FOOT_WORDS)
    if heads.any() and feet.any():
        with np.errstate(all="ignore"):
            head = np.nanmean(positions[:, heads].reshape(-1, 3), axis=0)
            foot = np.nanmean(positions[:, feet].reshape(-1, 3), axis=0)
        direction = head - foot
        if np.all(np.isfinite(direction)) and np.any(direction != 0):
            axis = int(np.argmax(np.abs(direction)))
            return ("+" if direction[axis] > 0 else "-") + "xyz"[axis]
    with np.errstate(all="ignore"):
        extent = np.nanmax(positions, axis=1) - np.nanmin(positions, axis=1)
        typical = np.nanmedian(extent, axis=0)
    if not np.all(np.isfinite(typical)):
        return "+y"
    return "+" + "xyz"[int(np.argmax(typical))]


def bones_from_parents(parents: IntArray, positions: FloatArray) -> IntArray:
    """Parent→child index pairs ``(B, 2)``, leaving out bones of zero length in every frame.

    Parameters
    ----------
    parents : ndarray, shape (J,)
        Parent per joint, -1 for roots.
    positions : ndarray, shape (F, J, 3)
        World positions, used only to find zero-length bones.
    """
    children = np.flatnonzero(np.asarray(parents) >= 0)
    pairs: IntArray = np.stack([np.asarray(parents)[children], children], axis=1).astype(np.intp)
    if len(pairs) == 0:
        return pairs.reshape(0, 2)
    lengths = np.linalg.norm(positions[:, pairs[:, 1]] - positions[:, pairs[:, 0]], axis=-1)
    scale = float(np.nanmax(np.abs(positions))) if positions.size else 1.0
    keep = np.nanmax(lengths, axis=0) > 1e-9 * max(scale, 1.0)
    kept: IntArray = pairs[keep]
    return kept


@dataclass(frozen=True, slots=True)
class SkeletonTrack:
    """Positions over time plus the bones joining them, ready to draw.

    Parameters
    ----------
    names : tuple of str
        Joint or keypoint names, length J.
    positions : ndarray, shape (F, J, 3)
        World positions in file units; NaN where missing.
    bones : ndarray, shape (B, 2)
        Index pairs (parent, child); may be empty (points only).
    up_axis : str
        One of :data:`UP_AXES`.
    fps : float
        Frames per second.
    """

    names: tuple[str, ...]
    positions: FloatArray
    bones: IntArray
    up_axis: str = "+y"
    fps: float = 30.0

    def __post_init__(self) -> None:
        positions = as_float_array(
            self.positions, "positions", ("F", len(self.names), 3), finite=False
        )
        if positions.shape[0] == 0:
            raise ShapeError("Expected at least one frame in `positions`, got 0")
        bones = np.asarray(self.bones, dtype=np.intp).reshape(-1, 2)
        if bones.size and (bones.min() < 0 or bones.max() >= len(self.names)):
            raise ShapeError(f"Expected bone indices in [0, {len(self.names)}), got {bones.max()}")
        up_vector(self.up_axis)
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "bones", bones)

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.positions.shape[0])

    @property
    def height(self) -> float:
        """Median per-frame extent along the up axis (file units, > 0)."""
        axis = "xyz".index(self.up_axis[1])
        with np.errstate(all="ignore"):
            values = self.positions[..., axis]
            extent = np.nanmax(values, axis=1) - np.nanmin(values, axis=1)
            height = float(np.nanmedian(extent))
        return height if np.isfinite(height) and height > 0 else 1.0


def check_same_shape(raw: SkeletonTrack, corrected: SkeletonTrack) -> None:
    """Raise ShapeError unless two tracks have the same frames and points."""
    if raw.positions.shape != corrected.positions.shape:
        raise ShapeError(
            f"Expected corrected positions of shape {raw.positions.shape}, "
            f"got {corrected.positions.shape}"
        )


def track_from_motion(motion: Motion, up_axis: str | None = None) -> SkeletonTrack:
    """Build a track from a BVH motion through forward kinematics.

    Parameters
    ----------
    motion : Motion
        The take.
    up_axis : str, optional
        Override of the detected up axis.
    """
    _, positions = forward_kinematics(motion)
    names = motion.skeleton.names
    return SkeletonTrack(
        names=names,
        positions=positions,
        bones=bones_from_parents(motion.skeleton.parents, positions),
        up_axis=up_axis or detect_up_axis(positions, names),
        fps=float(motion.fps),
    )


def track_from_keypoints(sequence: KeypointSequence, up_axis: str | None = None) -> SkeletonTrack:
    """Build a track from keypoints; bones come from a known layout, else points only.

    Parameters
    ----------
    sequence : KeypointSequence
        The keypoints (2D data are drawn in their image plane, y down).
    up_axis : str, optional
        Override of the detected up axis.
    """
    names = sequence.names
    positions = sequence.positions
    if up_axis is None:
        up_axis = "-y" if sequence.n_dims == 2 else detect_up_axis(positions, names)
    return SkeletonTrack(
        names=names,
        positions=positions,
        bones=bones_for_keypoints(names),
        up_axis=up_axis,
        fps=sequence.fps,
    )


def track_from_points(
    names: tuple[str, ...] | list[str],
    parents: list[int] | IntArray,
    positions: FloatArray,
    fps: float,
    up_axis: str | None = None,
) -> SkeletonTrack:
    """Build a track from a stored run's points (joints and End Sites, or keypoints).

    Parameters
    ----------
    names : sequence of str
        Point names, length P.
    parents : sequence of int
        Parent per point, -1 for roots; all -1 for keypoints, whose bones then come from a
        known layout.
    positions : ndarray, shape (F, P, 3)
        World positions, file units.
    fps : float
        Frames per second.
    up_axis : str, optional
        Override of the detected up axis.
    """
    names = tuple(str(n) for n in names)
    positions = np.asarray(positions, dtype=np.float64)
    parent_array = np.asarray(parents, dtype=np.intp)
    if parent_array.shape != (len(names),):
        raise ShapeError(f"Expected {len(names)} parents, got {parent_array.shape[0]}")
    if np.any(parent_array >= 0):
        bones = bones_from_parents(parent_array, positions)
    else:
        bones = bones_for_keypoints(names)
    return SkeletonTrack(
        names=names,
        positions=positions,
        bones=bones,
        up_axis=up_axis or detect_up_axis(positions, names),
        fps=float(fps),
    )


@dataclass(frozen=True, slots=True)
class CameraView:
    """A camera: where it is, what it looks at and which way is up (world units).

    Parameters
    ----------
    position, focal_point, view_up : tuple of float
        Camera position, look-at point and up direction.
    floor_height : float
        Coordinate of the floor along the up axis.
    floor_extent : tuple of float
        ``(min_a, max_a, min_b, max_b)`` of the floor grid on the two horizontal axes.
    """

    position: tuple[float, float, float]
    focal_point: tuple[float, float, float]
    view_up: tuple[float, float, float]
    floor_height: float
    floor_extent: tuple[float, float, float, float]


def frame_camera(
    track: SkeletonTrack,
    frames: tuple[int, int] | None = None,
    azimuth_deg: float = 35.0,
    elevation_deg: float = 15.0,
    aspect: float = 4 / 3,
) -> CameraView:
    """A camera that keeps frames ``start..end-1`` (default: the whole take) in view.

    Parameters
    ----------
    track : SkeletonTrack
        The skeleton.
    frames : tuple of int, optional
        Half-open frame range ``(start, end)``.
    azimuth_deg, elevation_deg : float
        Viewing direction, degrees, from the first horizontal axis and above the floor.
    aspect : float
        Width / height of the viewport.
    """
    start, end = frames if frames is not None else (0, track.n_frames)
    chunk = track.positions[max(start, 0) : max(end, start + 1)].reshape(-1, 3)
    chunk = chunk[np.all(np.isfinite(chunk), axis=1)]
    if len(chunk) == 0:
        chunk = np.zeros((1, 3))
    if len(chunk) > 20000:
        chunk = chunk[:: len(chunk) // 20000 + 1]
    low, high = chunk.min(axis=0), chunk.max(axis=0)
    up = up_vector(track.up_axis)
    up_index = "xyz".index(track.up_axis[1])
    horizontal = [i for i in range(3) if i != up_index]
    centre = (low + high) / 2
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    direction = np.zeros(3)
    direction[horizontal[0]] = np.cos(az) * np.cos(el)
    direction[horizontal[1]] = np.sin(az) * np.cos(el)
    direction += np.sin(el) * up
    right = np.cross(up, direction)
    right /= np.linalg.norm(right)
    screen_up = np.cross(direction, right)
    # Distance at which every point projects inside the view cone, with a small margin.
    relative = chunk - centre
    half_height = max(0.3 * track.height, 1e-9)
    across = np.maximum(np.abs(relative @ right), half_height / 4)
    along = np.maximum(np.abs(relative @ screen_up), half_height / 4)
    depth = relative @ direction
    tan_v = np.tan(np.radians(_VIEW_ANGLE_DEG) / 2)
    needed = np.maximum(across / (tan_v * aspect), along / tan_v) + depth
    distance = 1.3 * float(np.max(needed)) + 0.05 * track.height
    floor = float(low[up_index] if up[up_index] > 0 else high[up_index])
    margin = 0.3 * track.height
    extent = (
        float(low[horizontal[0]] - margin),
        float(high[horizontal[0]] + margin),
        float(low[horizontal[1]] - margin),
        float(high[horizontal[1]] + margin),
    )
    position = centre + distance * direction
    return CameraView(
        position=(float(position[0]), float(position[1]), float(position[2])),
        focal_point=(float(centre[0]), float(centre[1]), float(centre[2])),
        view_up=(float(up[0]), float(up[1]), float(up[2])),
        floor_height=floor,
        floor_extent=extent,
    )
