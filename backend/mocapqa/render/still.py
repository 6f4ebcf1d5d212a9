"""Still images of a skeleton: one pose, raw | corrected side by side, and thumbnails.

Conventions
-----------
Each function returns an ``(H, W, 3)`` uint8 image and must be called from the one render
thread (see :mod:`mocapqa.render.engine`). The camera frames the whole take unless a camera is
given, so stills of one take share a viewpoint. Flagged joints are red with a legend naming
them; in the corrected view the same joints are green.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray
from mocapqa.errors import ShapeError
from mocapqa.render.engine import FIXED_COLOR, FLAG_COLOR, CanvasPool, ImageArray, pool_or_own
from mocapqa.render.scene import CameraView, SkeletonTrack, check_same_shape, frame_camera

__all__ = [
    "MAX_SIDE_PX",
    "MIN_SIDE_PX",
    "StillOptions",
    "check_frame",
    "flags_at",
    "render_side_by_side",
    "render_still",
    "render_thumbnail",
]


MIN_SIDE_PX = 16
"""Smallest side of one view, pixels."""
MAX_SIDE_PX = 8192
"""Largest side of one view, pixels: an 8192 × 8192 view side by side (16384 px wide) takes
20 s and 7 GB; 100,000 px aborted VTK."""


@dataclass(frozen=True, slots=True)
class StillOptions:
    """Image size and viewpoint of stills.

    Parameters
    ----------
    width_px, height_px : int
        Size of one view in pixels, :data:`MIN_SIDE_PX` to :data:`MAX_SIDE_PX` (side by side
        doubles the width).
    azimuth_deg, elevation_deg : float
        Viewing direction, degrees.
    """

    width_px: int = 640
    height_px: int = 480
    azimuth_deg: float = 35.0
    elevation_deg: float = 15.0

    def __post_init__(self) -> None:
        if not (
            MIN_SIDE_PX <= self.width_px <= MAX_SIDE_PX
            and MIN_SIDE_PX <= self.height_px <= MAX_SIDE_PX
        ):
            raise ShapeError(
                f"Expected an image width and height of {MIN_SIDE_PX} to {MAX_SIDE_PX} px, "
                f"got {self.width_px}×{self.height_px}"
            )


def check_frame(track: SkeletonTrack, frame: int) -> None:
    """Raise ShapeError unless ``0 <= frame < track.n_frames``."""
    if not 0 <= frame < track.n_frames:
        raise ShapeError(f"Expected a frame in [0, {track.n_frames - 1}], got {frame}")


def flags_at(flagged: BoolArray | None, frame: int, n_joints: int) -> BoolArray:
    """The ``(J,)`` flag row for ``frame`` from a ``(J,)`` or ``(F, J)`` mask (or none)."""
    if flagged is None:
        return np.zeros(n_joints, dtype=bool)
    mask = np.asarray(flagged, dtype=bool)
    row = mask[frame] if mask.ndim == 2 else mask
    if row.shape != (n_joints,):
        raise ShapeError(
            f"Expected `flagged` to have shape (J,) or (F, J) with J={n_joints}, got {mask.shape}"
        )
    return row


def render_still(
    track: SkeletonTrack,
    frame: int,
    flagged: BoolArray | None = None,
    title: str | None = None,
    options: StillOptions | None = None,
    camera: CameraView | None = None,
    canvases: CanvasPool | None = None,
    legend: bool = True,
) -> ImageArray:
    """One pose of the skeleton: bone tubes, joint spheres, floor grid.

    Parameters
    ----------
    track : SkeletonTrack
        The skeleton.
    frame : int
        Frame index, 0-based.
    flagged : ndarray of bool, shape (J,) or (F, J), optional
        Joints to colour and name in a legend.
    title : str, optional
        Caption in the top-left corner (default: the frame number).
    options : StillOptions, optional
        Size and viewpoint.
    camera : CameraView, optional
        Overrides the whole-take framing.
    canvases : CanvasPool, optional
        Reused windows; a temporary one is used (and closed) when omitted.
    legend : bool
        Whether to name the flagged joints in a legend.

    Returns
    -------
    ndarray, shape (H, W, 3), uint8
    """
    options = options or StillOptions()
    check_frame(track, frame)
    camera = camera or frame_camera(
        track,
        None,
        options.azimuth_deg,
        options.elevation_deg,
        options.width_px / options.height_px,
    )
    with pool_or_own(canvases) as pool:
        canvas = pool.get(options.width_px, options.height_px, 1)
        canvas.draw(
            0,
            track,
            frame,
            camera,
            flags_at(flagged, frame, len(track.names)),
            title if title is not None else f"frame {frame}",
            legend=legend,
        )
        return canvas.image()


def render_side_by_side(
    raw: SkeletonTrack,
    corrected: SkeletonTrack,
    frame: int,
    flagged: BoolArray | None = None,
    titles: tuple[str, str] = ("raw", "corrected"),
    options: StillOptions | None = None,
    camera: CameraView | None = None,
    canvases: CanvasPool | None = None,
) -> ImageArray:
    """Raw and corrected poses of one frame in one image, raw on the left, same camera.

    Parameters
    ----------
    raw, corrected : SkeletonTrack
        The two versions of the take (same joints and frame count).
    frame : int
        Frame index, 0-based.
    flagged : ndarray of bool, shape (J,) or (F, J), optional
        Joints flagged in the raw take (red on the left, green on the right).
    titles : tuple of str
        Captions of the two views.
    options : StillOptions, optional
        Size of each view and viewpoint.
    camera : CameraView, optional
        Overrides the whole-take framing of the raw take.
    canvases : CanvasPool, optional
        Reused windows.

    Returns
    -------
    ndarray, shape (H, 2 W, 3), uint8
    """
    options = options or StillOptions()
    check_same_shape(raw, corrected)
    check_frame(raw, frame)
    camera = camera or frame_camera(
        raw, None, options.azimuth_deg, options.elevation_deg, options.width_px / options.height_px
    )
    row = flags_at(flagged, frame, len(raw.names))
    with pool_or_own(canvases) as pool:
        canvas = pool.get(2 * options.width_px, options.height_px, 2)
        captions = [f"{t} · frame {frame}" if t else f"frame {frame}" for t in titles]
        canvas.draw(0, raw, frame, camera, row, captions[0], FLAG_COLOR)
        canvas.draw(1, corrected, frame, camera, row, captions[1], FIXED_COLOR)
        return canvas.image()


def render_thumbnail(
    track: SkeletonTrack,
    frame: int | None = None,
    width_px: int = 192,
    height_px: int = 144,
    canvases: CanvasPool | None = None,
) -> ImageArray:
    """A small untitled still for take lists (default: the middle frame).

    Returns
    -------
    ndarray, shape (height_px, width_px, 3), uint8
    """
    frame = track.n_frames // 2 if frame is None else frame
    return render_still(
        track,
        frame,
        title="",
        options=StillOptions(width_px=width_px, height_px=height_px),
        canvases=canvases,
    )
