"""Contact sheets: one tile per flagged interval, at the interval's frame of largest error.

Conventions
-----------
A tile shows the raw pose (flagged joints red) and, when a corrected take is given, the
corrected pose beside it (same joints green), with the camera framed on that pose so small
twists stay visible. Tiles are laid out row by row on a white sheet with a gap between them.
The frame of largest error is where raw and corrected positions differ most inside the
interval; with no corrected take (or no difference) it is the interval's middle frame. An
interval the corrected take does not fix shows no corrected pose: one found but not applied
(``applied`` false in the run's findings, as a low-confidence interval under
``apply=confident``) or never corrected (a limb spin) keeps the raw pose alone, its second view
empty but for the caption ("not applied (confidence 0.14)"), at the interval's middle frame.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import ShapeError
from mocapqa.render.engine import (
    FIXED_COLOR,
    FLAG_COLOR,
    Canvas,
    CanvasPool,
    ImageArray,
    pool_or_own,
)
from mocapqa.render.scene import SkeletonTrack, check_same_shape, frame_camera

__all__ = [
    "SheetTile",
    "frame_of_largest_difference",
    "not_applied_reason",
    "render_contact_sheet",
    "tiles_from_intervals",
]

_GAP_PX = 8


@dataclass(frozen=True, slots=True)
class SheetTile:
    """One tile of a contact sheet.

    Parameters
    ----------
    frame : int
        Frame to draw, 0-based.
    joints : tuple of int
        Flagged joint indices.
    label : str
        Caption (joint, frames, offset or violation).
    not_applied : str, optional
        Why the corrected take does not fix this interval ("not applied (confidence 0.14)",
        "not corrected (limb spin)"); the tile then shows no corrected pose. None when it does.
    """

    frame: int
    joints: tuple[int, ...]
    label: str
    not_applied: str | None = None


def frame_of_largest_difference(
    raw_positions: FloatArray,
    corrected_positions: FloatArray | None,
    start_frame: int,
    end_frame: int,
) -> int:
    """Frame in ``[start_frame, end_frame]`` where raw and corrected positions differ most.

    Parameters
    ----------
    raw_positions, corrected_positions : ndarray, shape (F, J, 3)
        World positions; ``corrected_positions`` may be None.
    start_frame, end_frame : int
        Inclusive frame range, 0-based.

    Returns
    -------
    int
        The frame index (the middle of the range when nothing differs).
    """
    n_frames = raw_positions.shape[0]
    start = int(np.clip(start_frame, 0, n_frames - 1))
    end = int(np.clip(end_frame, start, n_frames - 1))
    middle = (start + end) // 2
    if corrected_positions is None:
        return middle
    gap = np.linalg.norm(
        raw_positions[start : end + 1] - corrected_positions[start : end + 1], axis=-1
    )
    per_frame = np.nanmax(np.nan_to_num(gap, nan=0.0), axis=1)
    if not np.any(per_frame > 0):
        return middle
    return start + int(np.argmax(per_frame))


def _two_lines(label: str) -> str:
    # Break after the joint name so long captions stay inside their view.
    parts = label.split(" · ")
    return " · ".join(parts[:2]) + ("\n" + " · ".join(parts[2:]) if len(parts) > 2 else "")


def _joint_index(value: Any, names: Sequence[str]) -> int | None:
    if isinstance(value, (int, np.integer)) and 0 <= int(value) < len(names):
        return int(value)
    if isinstance(value, str) and value in names:
        return list(names).index(value)
    return None


def not_applied_reason(record: Mapping[str, Any]) -> str | None:
    """Why the corrected take does not fix an interval record, or None when it does.

    A limb spin (``kind`` "spin") is never corrected; a record with ``applied`` false was found
    but not applied (its ``confidence`` is quoted when given). A record without ``applied``
    (a limit violation, an interval list of other origin) counts as shown corrected.
    """
    if record.get("kind") == "spin":
        return "not corrected (limb spin)"
    if "applied" in record and not record["applied"]:
        confidence = record.get("confidence")
        if confidence is None:
            return "not applied"
        return f"not applied (confidence {float(confidence):.2f})"
    return None


def tiles_from_intervals(
    intervals: Sequence[Mapping[str, Any]],
    raw: SkeletonTrack,
    corrected: SkeletonTrack | None = None,
) -> list[SheetTile]:
    """Tiles for interval records such as the ``intervals`` of a twist analysis' JSON.

    Parameters
    ----------
    intervals : sequence of mapping
        Each with ``joint`` (name or index), ``start_frame`` and ``end_frame`` (inclusive), and
        optionally ``offset_deg`` or ``violation_deg`` for the caption (``kind`` "spin":
        captioned as a limb spin, not corrected), ``applied`` and ``confidence`` (an interval
        not applied gets no corrected pose, see :func:`not_applied_reason`). Records naming an
        unknown joint are skipped.
    raw, corrected : SkeletonTrack
        The takes; ``corrected`` picks the frame of largest error of an applied interval.
    """
    tiles = []
    for record in intervals:
        joint = _joint_index(record.get("joint"), raw.names)
        if joint is None:
            continue
        start, end = int(record.get("start_frame", 0)), int(record.get("end_frame", 0))
        reason = not_applied_reason(record)
        # Where the corrected take differs inside an interval it does not fix says nothing
        # about that interval (another fix or the filter moved the pose).
        fixed = None if corrected is None or reason is not None else corrected.positions
        frame = frame_of_largest_difference(raw.positions, fixed, start, end)
        frames = f"frame {start}" if start == end else f"frames {start}–{end}"
        label = f"{raw.names[joint]} · {frames}"
        if record.get("kind") == "spin" and record.get("offset_deg") is not None:
            # A limb spin is reported, never corrected: both panels show the raw pose.
            label += f" · spin {float(record['offset_deg']):+.1f}° (not corrected)"
        elif record.get("offset_deg") is not None:
            label += f" · offset {float(record['offset_deg']):+.1f}°"
        if record.get("violation_deg") is not None:
            label += f" · violation {float(record['violation_deg']):.1f}°"
        tiles.append(SheetTile(frame=frame, joints=(joint,), label=label, not_applied=reason))
    return tiles


def render_contact_sheet(
    raw: SkeletonTrack,
    tiles: Sequence[SheetTile],
    corrected: SkeletonTrack | None = None,
    columns: int = 2,
    tile_width_px: int = 300,
    tile_height_px: int = 300,
    canvases: CanvasPool | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> ImageArray:
    """Draw the tiles on one sheet.

    Parameters
    ----------
    raw : SkeletonTrack
        The take as recorded.
    tiles : sequence of SheetTile
        At least one tile.
    corrected : SkeletonTrack, optional
        The corrected take; each tile then shows raw | corrected, except a tile whose
        ``not_applied`` is set: its second view holds that caption and no pose.
    columns : int
        Tiles per row.
    tile_width_px, tile_height_px : int
        Size of one view; a raw | corrected tile is twice as wide.
    canvases : CanvasPool, optional
        Reused windows.
    progress : callable, optional
        Called with ``(done, total)`` after each tile.

    Returns
    -------
    ndarray, shape (H, W, 3), uint8
    """
    if not tiles:
        raise ShapeError("Expected at least one tile for a contact sheet, got none")
    if corrected is not None:
        check_same_shape(raw, corrected)
    views = 1 if corrected is None else 2
    images = []
    with pool_or_own(canvases) as pool:
        for done, tile in enumerate(tiles, start=1):
            if not 0 <= tile.frame < raw.n_frames:
                raise ShapeError(
                    f"Expected tile frames in [0, {raw.n_frames - 1}], got {tile.frame}"
                )
            canvas = pool.get(views * tile_width_px, tile_height_px, views)
            _draw_tile(canvas, raw, tile, corrected, tile_width_px / tile_height_px)
            images.append(canvas.image())
            if progress is not None:
                progress(done, len(tiles))
    return _lay_out(images, columns)


def _draw_tile(
    canvas: Canvas,
    raw: SkeletonTrack,
    tile: SheetTile,
    corrected: SkeletonTrack | None,
    aspect: float,
) -> None:
    """Draw one tile: the raw pose, then the corrected pose or why there is none."""
    flagged = np.zeros(len(raw.names), dtype=bool)
    flagged[list(tile.joints)] = True
    camera = frame_camera(raw, (tile.frame, tile.frame + 1), aspect=aspect)
    caption = f"raw · {tile.label}"
    if corrected is None and tile.not_applied is not None:
        caption += f" · {tile.not_applied}"
    canvas.draw(0, raw, tile.frame, camera, flagged, _two_lines(caption), FLAG_COLOR, legend=False)
    if corrected is not None and tile.not_applied is not None:
        # No corrected pose for an interval the corrected take does not fix.
        canvas.caption(1, f"{tile.not_applied}:\nraw pose only, nothing corrected")
    elif corrected is not None:
        canvas.draw(
            1, corrected, tile.frame, camera, flagged, "corrected", FIXED_COLOR, legend=False
        )


def _lay_out(images: Sequence[ImageArray], columns: int) -> ImageArray:
    """The images row by row on a white sheet, :data:`_GAP_PX` apart and from its edges."""
    columns = max(1, min(columns, len(images)))
    rows = -(-len(images) // columns)
    tile_h, tile_w = images[0].shape[:2]
    sheet = np.full(
        (rows * tile_h + (rows + 1) * _GAP_PX, columns * tile_w + (columns + 1) * _GAP_PX, 3),
        255,
        dtype=np.uint8,
    )
    for k, image in enumerate(images):
        r, c = divmod(k, columns)
        top, left = _GAP_PX + r * (tile_h + _GAP_PX), _GAP_PX + c * (tile_w + _GAP_PX)
        sheet[top : top + tile_h, left : left + tile_w] = image
    return sheet
