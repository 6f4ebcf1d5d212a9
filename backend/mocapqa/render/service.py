"""RenderService: every render of a process goes through one dedicated thread.

Conventions
-----------
VTK corrupts its heap when two threads render at once, so request handlers never call the
drawing functions directly: they call a :class:`RenderService`, which queues the work on its
single worker thread and waits for the PNG bytes. The worker keeps its canvases open between
calls, so only the first image pays VTK's start-up. The alternative, a spawn/forkserver
process pool, isolates crashes too but pays start-up once per process and copies every track
across; one thread is enough for images that take a fraction of a second.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from mocapqa.core.arrays import BoolArray
from mocapqa.render.clip import encode_clip, render_clip_frames
from mocapqa.render.engine import CanvasPool, png_bytes
from mocapqa.render.scene import SkeletonTrack
from mocapqa.render.sheet import SheetTile, render_contact_sheet
from mocapqa.render.still import (
    StillOptions,
    render_side_by_side,
    render_still,
    render_thumbnail,
)

__all__ = ["RenderService"]

T = TypeVar("T")


class RenderService:
    """A single render thread with methods returning image bytes.

    Parameters
    ----------
    timeout_s : float
        Longest wait for one result, seconds.

    Examples
    --------
    >>> with RenderService() as service:  # doctest: +SKIP
    ...     png = service.still(track, frame=10)
    """

    def __init__(self, timeout_s: float = 120.0) -> None:
        self.timeout_s = timeout_s
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="mocapqa-render")
        self._canvases: CanvasPool | None = None

    def _pool(self) -> CanvasPool:
        # Runs on the worker thread only, so the canvases are created and used there.
        if self._canvases is None:
            self._canvases = CanvasPool()
        return self._canvases

    def _run(self, work: Callable[[CanvasPool], T]) -> T:
        future = self._executor.submit(lambda: work(self._pool()))
        return future.result(timeout=self.timeout_s)

    def thumbnail(
        self,
        track: SkeletonTrack,
        frame: int | None = None,
        width_px: int = 192,
        height_px: int = 144,
    ) -> bytes:
        """PNG of a small untitled still (default: the middle frame)."""
        return self._run(
            lambda pool: png_bytes(
                render_thumbnail(track, frame, width_px, height_px, canvases=pool)
            )
        )

    def still(
        self,
        track: SkeletonTrack,
        frame: int,
        flagged: BoolArray | None = None,
        title: str | None = None,
        options: StillOptions | None = None,
    ) -> bytes:
        """PNG of one pose; see :func:`mocapqa.render.still.render_still`."""
        return self._run(
            lambda pool: png_bytes(
                render_still(track, frame, flagged, title, options, canvases=pool)
            )
        )

    def side_by_side(
        self,
        raw: SkeletonTrack,
        corrected: SkeletonTrack,
        frame: int,
        flagged: BoolArray | None = None,
        options: StillOptions | None = None,
    ) -> bytes:
        """PNG of raw | corrected; see :func:`mocapqa.render.still.render_side_by_side`."""
        return self._run(
            lambda pool: png_bytes(
                render_side_by_side(raw, corrected, frame, flagged, options=options, canvases=pool)
            )
        )

    def contact_sheet(
        self,
        raw: SkeletonTrack,
        tiles: Sequence[SheetTile],
        corrected: SkeletonTrack | None = None,
        columns: int = 2,
        progress: Callable[[int, int], None] | None = None,
    ) -> bytes:
        """PNG of a contact sheet; see :func:`mocapqa.render.sheet.render_contact_sheet`."""
        return self._run(
            lambda pool: png_bytes(
                render_contact_sheet(
                    raw, tiles, corrected, columns, canvases=pool, progress=progress
                )
            )
        )

    def clip(
        self,
        raw: SkeletonTrack,
        start_frame: int,
        end_frame: int,
        corrected: SkeletonTrack | None = None,
        flagged: BoolArray | None = None,
        fmt: str = "gif",
        progress: Callable[[int, int], None] | None = None,
    ) -> bytes:
        """GIF or MP4 bytes of an interval; see :mod:`mocapqa.render.clip`."""

        def work(pool: CanvasPool) -> bytes:
            frames = render_clip_frames(
                raw, start_frame, end_frame, corrected, flagged, canvases=pool, progress=progress
            )
            return encode_clip(frames, fmt, raw.fps)

        return self._run(work)

    def close(self) -> None:
        """Close the canvases and stop the thread."""

        def shutdown(pool: CanvasPool) -> None:
            pool.close()

        if self._canvases is not None:
            self._run(shutdown)
        self._executor.shutdown(wait=True)

    def __enter__(self) -> RenderService:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
