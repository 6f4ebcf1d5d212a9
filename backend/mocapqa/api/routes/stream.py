"""``WS /stream/filter``: filter a live keypoint stream frame by frame.

Protocol (JSON text messages): the client first sends ``{"fps": 30, "n_keypoints": K}``, with
optionally ``"length_unit"`` (m, cm, mm, in, px, normalized, unknown; default unknown) and
``"preset"`` (a preset of the adaptive filter; default ``default``), then
one ``{"positions": [[x, y, z], ...], "confidence": [...]}`` per frame; the server answers each
frame with ``{"frame": i, "positions": [...], "weights": {...}}``, or ``{"error": message}``
and closes on bad input (code 1003), a message or keypoint count over the limits (1009) or
frames faster than allowed (1008).
"""

from __future__ import annotations

import json
from typing import Any

from fastapi import APIRouter, WebSocket, WebSocketDisconnect
from starlette.concurrency import run_in_threadpool

from mocapqa.api.http_guards import RateWindow, origin_allowed
from mocapqa.config import Settings
from mocapqa.errors import MocapQAError, RateLimitError, TooLargeError
from mocapqa.io.formats import MAX_FPS
from mocapqa.pipeline.filtering import StreamSession

__all__ = ["router"]

router = APIRouter(tags=["stream"])
"""Routes of this resource, included under ``/api/v1``."""


def _number(message: dict[str, Any], key: str) -> float:
    value = message.get(key)
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise TypeError(f"Expected a number for {key!r}, got {value!r}")
    return float(value)


def _text(message: dict[str, Any], key: str, default: str) -> str:
    value = message.get(key, default)
    if not isinstance(value, str):
        raise TypeError(f"Expected a string for {key!r}, got {value!r}")
    return value


def _receive_limit(text: str, max_bytes: int) -> Any:
    if len(text) > max_bytes:
        raise TooLargeError(
            f"Expected messages of at most {max_bytes} bytes (setting stream_max_frame_bytes), "
            f"got {len(text)}"
        )
    return json.loads(text)


_HEADER_KEYS = frozenset({"fps", "n_keypoints", "length_unit", "preset"})


def _session(first: Any, settings: Settings) -> StreamSession:
    if not isinstance(first, dict):
        raise TypeError(f"Expected a JSON object first, got {type(first).__name__}")
    n_keypoints = _number(first, "n_keypoints")
    if not 1 <= n_keypoints <= settings.stream_max_keypoints:
        raise TooLargeError(
            f"Expected n_keypoints from 1 to {settings.stream_max_keypoints} (setting "
            f"stream_max_keypoints), got {n_keypoints:g}"
        )
    if n_keypoints != int(n_keypoints):
        raise TypeError(f"Expected a whole number for 'n_keypoints', got {n_keypoints:g}")
    fps = _number(first, "fps")
    if not 0 < fps <= MAX_FPS:
        raise ValueError(f"Expected 'fps' above 0 and at most {MAX_FPS:g}, got {fps:g}")
    extra = sorted(set(first) - _HEADER_KEYS)
    if extra:
        raise TypeError(f"Expected only the keys {sorted(_HEADER_KEYS)} first, got {extra}")
    return StreamSession(
        fps,
        int(n_keypoints),
        _text(first, "length_unit", "unknown"),
        _text(first, "preset", "default"),
    )


@router.websocket("/stream/filter")
async def stream_filter(websocket: WebSocket) -> None:
    """Filter frames as they arrive with the streaming adaptive filter.

    A browser connection from another site (its ``Origin`` not this server's host nor in
    ``cors_origins``) is refused before the handshake completes (403). The filter runs on a
    worker thread, never on the event loop; ``stream_max_keypoints``,
    ``stream_max_frame_bytes`` and ``stream_max_frames_per_s`` bound one stream's cost.
    """
    settings = websocket.app.state.services.settings
    if not origin_allowed(websocket.headers, settings.cors_origins):
        await websocket.close(code=1008, reason="cross-site connection refused")
        return
    await websocket.accept()
    max_bytes = settings.stream_max_frame_bytes
    rate = RateWindow(max(1, int(settings.stream_max_frames_per_s)), window_s=1.0)
    try:
        first = _receive_limit(await websocket.receive_text(), max_bytes)
        session = await run_in_threadpool(_session, first, settings)
        await websocket.send_json(
            {
                "ready": True,
                "n_keypoints": session.n_keypoints,
                "length_unit": session.length_unit,
                "preset": session.preset,
            }
        )
        while True:
            message = _receive_limit(await websocket.receive_text(), max_bytes)
            if rate.admit("frames") > 0:
                raise RateLimitError(
                    f"Expected at most {settings.stream_max_frames_per_s:g} frames per second "
                    "(setting stream_max_frames_per_s), got more",
                    retry_after_s=1,
                )
            if not isinstance(message, dict):
                raise TypeError(f"Expected a JSON object per frame, got {type(message).__name__}")
            answer = await run_in_threadpool(
                session.update, message.get("positions"), message.get("confidence")
            )
            await websocket.send_json(answer)
    except WebSocketDisconnect:
        return
    except (MocapQAError, TypeError, ValueError, AttributeError, RecursionError) as e:
        await websocket.send_json({"error": str(e)})
        code = 1009 if isinstance(e, TooLargeError) else 1003
        await websocket.close(code=1008 if isinstance(e, RateLimitError) else code)
