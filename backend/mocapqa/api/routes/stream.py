"""``WS /stream/filter``: filter a live keypoint stream frame by frame.

Protocol (JSON text messages): the client first sends ``{"fps": 30, "n_keypoints": K}``, with
optionally ``"length_unit"`` (m, cm, mm, in, px, normalized, unknown; default unknown) and
``"preset"`` (a preset of the adaptive filter; default ``default``), then
one ``{"positions": [[x, y, z], ...], "confidence": [...]}`` per frame; the server answers each
frame with ``{"frame": i, "positions": [...], "weights": {...}}``, or ``{"error": message}``
and closes (code 1003) on bad input.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, WebSocket, WebSocketDisconnect

from mocapqa.errors import MocapQAError
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


@router.websocket("/stream/filter")
async def stream_filter(websocket: WebSocket) -> None:
    """Filter frames as they arrive with the streaming adaptive filter."""
    await websocket.accept()
    try:
        first = await websocket.receive_json()
        if not isinstance(first, dict):
            raise TypeError(f"Expected a JSON object first, got {type(first).__name__}")
        session = StreamSession(
            _number(first, "fps"),
            int(_number(first, "n_keypoints")),
            _text(first, "length_unit", "unknown"),
            _text(first, "preset", "default"),
        )
        await websocket.send_json(
            {
                "ready": True,
                "n_keypoints": session.n_keypoints,
                "length_unit": session.length_unit,
                "preset": session.preset,
            }
        )
        while True:
            message = await websocket.receive_json()
            if not isinstance(message, dict):
                raise TypeError(f"Expected a JSON object per frame, got {type(message).__name__}")
            await websocket.send_json(
                session.update(message.get("positions"), message.get("confidence"))
            )
    except WebSocketDisconnect:
        return
    except (MocapQAError, TypeError, ValueError, AttributeError) as e:
        await websocket.send_json({"error": str(e)})
        await websocket.close(code=1003)
