"""Animated clips of an interval, raw | corrected side by side, as GIF or MP4 bytes.

Conventions
-----------
The camera is framed once on the whole interval so the figure does not jump between frames.
Frame sizes are rounded up to multiples of 16 px, which H.264 needs (and GIF does not mind).
Playback runs at the take's rate capped at 30 fps; a 120 fps take therefore plays slowed down,
which is what a reviewer wants for a short interval.
"""

from __future__ import annotations

import io
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import BoolArray
from mocapqa.errors import ShapeError
from mocapqa.render.engine import FIXED_COLOR, FLAG_COLOR, CanvasPool, ImageArray, pool_or_own
from mocapqa.render.scene import SkeletonTrack, check_same_shape, frame_camera
from mocapqa.render.still import flags_at

__all__ = ["CLIP_FORMATS", "encode_clip", "render_clip_frames"]

# Containers encode_clip writes.
CLIP_FORMATS = ("gif", "mp4")


def _multiple_of_16(value: int) -> int:
    return max(16, -(-value // 16) * 16)


def render_clip_frames(
    raw: SkeletonTrack,
    start_frame: int,
    end_frame: int,
    corrected: SkeletonTrack | None = None,
    flagged: BoolArray | None = None,
    width_px: int = 320,
    height_px: int = 320,
    canvases: CanvasPool | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[ImageArray]:
    """Images of frames ``start_frame..end_frame`` (inclusive).

    Parameters
    ----------
    raw : SkeletonTrack
        The take as recorded.
    start_frame, end_frame : int
        Inclusive frame range, 0-based.
    corrected : SkeletonTrack, optional
        Drawn to the right of the raw take.
    flagged : ndarray of bool, shape (J,) or (F, J), optional
        Joints to colour.
    width_px, height_px : int
        Size of one view, rounded up to a multiple of 16.
    canvases : CanvasPool, optional
        Reused windows.
    progress : callable, optional
        Called with ``(done, total)`` after each frame.

    Returns
    -------
    list of ndarray, each shape (H, W, 3) uint8
    """
    if not 0 <= start_frame <= end_frame < raw.n_frames:
        raise ShapeError(
            f"Expected 0 <= start <= end <= {raw.n_frames - 1}, got {start_frame}-{end_frame}"
        )
    if corrected is not None:
        check_same_shape(raw, corrected)
    width, height = _multiple_of_16(width_px), _multiple_of_16(height_px)
    views = 1 if corrected is None else 2
    camera = frame_camera(raw, (start_frame, end_frame + 1), aspect=width / height)
    frames = []
    total = end_frame - start_frame + 1
    with pool_or_own(canvases) as pool:
        for k, frame in enumerate(range(start_frame, end_frame + 1), start=1):
            row = flags_at(flagged, frame, len(raw.names))
            canvas = pool.get(views * width, height, views)
            canvas.draw(
                0, raw, frame, camera, row, f"raw · frame {frame}", FLAG_COLOR, legend=False
            )
            if corrected is not None:
                canvas.draw(
                    1, corrected, frame, camera, row, "corrected", FIXED_COLOR, legend=False
                )
            frames.append(canvas.image())
            if progress is not None:
                progress(k, total)
    return frames


def _gif_bytes(frames: list[ImageArray], rate: float) -> bytes:
    # One palette for the whole clip, taken from a sample of frames: quantising every frame
    # on its own cost more than rendering it, and made colours flicker between frames.
    from PIL import Image

    sample = np.concatenate([f[::2, ::2] for f in frames[:: max(1, len(frames) // 6)]], axis=0)
    palette = Image.fromarray(sample).quantize(colors=96, method=Image.Quantize.MEDIANCUT)
    images = [
        Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames
    ]
    buffer = io.BytesIO()
    images[0].save(
        buffer,
        format="GIF",
        save_all=True,
        append_images=images[1:],
        duration=round(1000.0 / rate),
        loop=0,
        disposal=1,
    )
    return buffer.getvalue()


def encode_clip(frames: list[ImageArray], fmt: str, fps: float) -> bytes:
    """Encode images as an animated GIF (looping) or an H.264 MP4.

    Parameters
    ----------
    frames : list of ndarray, each shape (H, W, 3) uint8
        Same-sized images.
    fmt : {"gif", "mp4"}
        Container.
    fps : float
        Playback rate, capped at 30.
    """
    if fmt not in CLIP_FORMATS:
        raise ShapeError(f"Expected a clip format in {CLIP_FORMATS}, got {fmt!r}")
    if not frames:
        raise ShapeError("Expected at least one frame, got none")
    rate = float(min(max(fps, 1.0), 30.0))
    if fmt == "gif":
        return _gif_bytes(frames, rate)
    import imageio.v2 as imageio

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "clip.mp4"
        writer = imageio.get_writer(
            path, fps=rate, codec="libx264", macro_block_size=16, quality=7, pixelformat="yuv420p"
        )
        try:
            for image in frames:
                writer.append_data(image)
        finally:
            writer.close()
        return path.read_bytes()
