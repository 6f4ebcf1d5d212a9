"""``WS /stream/filter``: filter a live keypoint stream frame by frame.

Protocol (JSON text messages): the client first sends ``{"fps": 30, "n_keypoints": K}``, with
optionally ``"length_unit"`` (m, cm, mm, in, px, normalized, unknown; default unknown) and
``"preset"`` (a preset of the adaptive filter; default ``default``), then
one ``{"positions": [[x, y, z], ...], "confidence": [...]}`` per frame; the server answers each
frame with ``{"frame": i, "positions": [...], "weights": {...}}``.

Every number is checked where it arrives, against the bounds every take keeps
(:mod:`mocapqa.core.bounds`): ``fps`` finite, from 0.1 to 100,000; ``n_keypoints`` a whole
number from 1 to ``stream_max_keypoints``; each coordinate a JSON number (or ``null``,
missing) within ±1e9, each confidence a number from 0 to 1 (or ``null``, 0). JSON's
``NaN`` and ``Infinity`` are not numbers here. A message the server cannot use is answered
with ``{"error": message}`` and the socket closed with a code and a reason (the message, cut
to the 123 bytes a close frame holds):

* 1003, unsupported data: a binary message;
* 1007, invalid payload: text that is not JSON, or JSON that is not the protocol's (a wrong
  type, a missing or extra header key, a number out of its bounds);
* 1008, policy: frames faster than ``stream_max_frames_per_s``;
* 1009, too big: a message over ``stream_max_frame_bytes`` or more keypoints than
  ``stream_max_keypoints``;
* 1011, internal error: anything else, which is a bug: the client reads "internal error",
  the log gets the traceback.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
from collections.abc import Mapping
from typing import Any, NoReturn

import anyio
import anyio.to_thread
from fastapi import APIRouter, WebSocket, WebSocketDisconnect
from starlette.concurrency import run_in_threadpool

from mocapqa.api.http_guards import RateWindow, origin_allowed
from mocapqa.config import Settings
from mocapqa.errors import (
    InputError,
    MocapQAError,
    RateLimitError,
    TooLargeError,
    UnsupportedFormatError,
)
from mocapqa.pipeline.filtering import StreamSession

__all__ = ["CLOSE_CODES", "router"]

log = logging.getLogger(__name__)

router = APIRouter(tags=["stream"])
"""Routes of this resource, included under ``/api/v1``."""

CLOSE_CODES: tuple[tuple[type[MocapQAError], int], ...] = (
    (UnsupportedFormatError, 1003),
    (TooLargeError, 1009),
    (InputError, 1007),
    (RateLimitError, 1008),
    (MocapQAError, 1008),
)
"""The WebSocket close code of each refusal, most specific class first (the first match
wins); any other exception closes with 1011 (internal error)."""
INTERNAL_ERROR = 1011
"""Close code of an error that is the server's, not the message's."""
_MAX_REASON_BYTES = 123
"""Longest close reason: a close frame's payload is at most 125 bytes, 2 of them the code."""
_HEADER_KEYS = frozenset({"fps", "n_keypoints", "length_unit", "preset"})
FRAME_THREADS = 2
"""Threads filtering stream frames at once, for all streams together: a machine's cores. The
other requests keep the server's remaining threads, so a room of live streams slows the
streams, not the dashboard."""


def _number(message: dict[str, Any], key: str) -> float:
    """A JSON number of ``message`` as a float; an integer past a float's range is infinite
    (every bound refuses it)."""
    value = message.get(key)
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise InputError(f"Expected a number for {key!r}, got {_shown(value)}")
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def _text(message: dict[str, Any], key: str, default: str) -> str:
    value = message.get(key, default)
    if not isinstance(value, str):
        raise InputError(f"Expected a string for {key!r}, got {_shown(value)}")
    return value


def _shown(value: Any) -> str:
    """A client's value for a message: a string, number, true, false or null as JSON (cut to
    40 characters), an array or object by its size."""
    if isinstance(value, list):
        return f"an array of {len(value)}"
    if isinstance(value, dict):
        return f"an object of {len(value)} keys"
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**16:
        return f"an integer of {len(str(abs(value)))} digits"
    text = json.dumps(value)
    return text if len(text) <= 40 else f"{text[:40]}…"


def _refuse_constant(name: str) -> NoReturn:
    raise InputError(f"Expected JSON numbers, got {name} (not a number in JSON)")


def _parse(message: Mapping[str, Any], max_bytes: int) -> Any:
    """The JSON value of a received WebSocket message.

    Raises
    ------
    WebSocketDisconnect
        When the client closed the socket.
    UnsupportedFormatError
        For a binary message.
    TooLargeError
        Over ``max_bytes``.
    InputError
        For text that is not JSON, nested too deep to parse, or holding NaN or Infinity.
    """
    if message["type"] == "websocket.disconnect":
        raise WebSocketDisconnect(message.get("code") or 1000, message.get("reason"))
    text = message.get("text")
    if text is None:
        raise UnsupportedFormatError(
            "Expected JSON text messages, got a binary message (send JSON as text)"
        )
    if len(text) > max_bytes:
        raise TooLargeError(
            f"Expected messages of at most {max_bytes} bytes (setting stream_max_frame_bytes), "
            f"got {len(text)}"
        )
    try:
        return json.loads(text, parse_constant=_refuse_constant)
    except json.JSONDecodeError as e:
        raise InputError(f"Expected a JSON message, got text that is not JSON ({e})") from e
    except ValueError as e:  # an integer longer than Python converts (4300 digits)
        raise InputError("Expected JSON numbers of at most 4300 digits, got a longer one") from e
    except RecursionError as e:
        raise InputError(
            "Expected a JSON message nested a few levels deep, got one nested too deep to parse"
        ) from e


def _session(first: Any, settings: Settings) -> StreamSession:
    if not isinstance(first, dict):
        raise InputError(f"Expected a JSON object first, got {_shown(first)}")
    n_keypoints = _number(first, "n_keypoints")
    if not 1 <= n_keypoints <= settings.stream_max_keypoints:
        raise TooLargeError(
            f"Expected n_keypoints from 1 to {settings.stream_max_keypoints} (setting "
            f"stream_max_keypoints), got {n_keypoints:g}"
        )
    if n_keypoints != int(n_keypoints):
        raise InputError(f"Expected a whole number for 'n_keypoints', got {n_keypoints:g}")
    fps = _number(first, "fps")
    extra = sorted(set(first) - _HEADER_KEYS)
    if extra:
        shown = [k[:40] for k in extra[:3]] + (["…"] if len(extra) > 3 else [])
        raise InputError(f"Expected only the keys {sorted(_HEADER_KEYS)} first, got {shown}")
    # The session checks the rate against the bounds every take keeps (io.formats.check_fps).
    return StreamSession(
        fps,
        int(n_keypoints),
        _text(first, "length_unit", "unknown"),
        _text(first, "preset", "default"),
    )


def _numbers(values: Any, name: str, size: int, what: str) -> list[float]:
    """``size`` JSON numbers or nulls (NaN) as floats; integers past a float's range are
    infinite (the session's bounds refuse them)."""
    if not isinstance(values, list) or len(values) != size:
        raise InputError(f"Expected {name} as {what}, got {_shown(values)}")
    out = []
    for value in values:
        if value is None:
            out.append(math.nan)
        elif isinstance(value, int | float) and not isinstance(value, bool):
            try:
                out.append(float(value))
            except OverflowError:
                out.append(math.inf)
        else:
            raise InputError(f"Expected {name} to hold numbers or null, got {_shown(value)}")
    return out


def _frame(message: Any, k: int) -> tuple[list[list[float]], list[float] | None]:
    """The positions and confidence of a frame message, as JSON numbers (null: missing)."""
    if not isinstance(message, dict):
        raise InputError(f"Expected a JSON object per frame, got {_shown(message)}")
    positions = message.get("positions")
    rows = f"{k} rows of [x, y, z] (numbers or null)"
    if not isinstance(positions, list) or len(positions) != k:
        raise InputError(f"Expected positions as {rows}, got {_shown(positions)}")
    frame = [_numbers(row, f"positions row {i}", 3, "[x, y, z]") for i, row in enumerate(positions)]
    confidence = message.get("confidence")
    if confidence is None:
        return frame, None
    return frame, _numbers(confidence, "confidence", k, f"{k} values (numbers or null)")


def _answer(session: StreamSession, received: Mapping[str, Any], max_bytes: int) -> str:
    """The answer to one frame message, as JSON text: parsed, checked, filtered and written
    on a worker thread, so the event loop only moves bytes (with 50 streams of 1,000
    keypoints, parsing and writing on the loop kept ``/health`` waiting a second)."""
    positions, confidence = _frame(_parse(received, max_bytes), session.n_keypoints)
    return json.dumps(
        session.update(positions, confidence), separators=(",", ":"), ensure_ascii=False
    )


def _frame_limiter(websocket: WebSocket) -> anyio.CapacityLimiter:
    """The app's threads for stream frames (:data:`FRAME_THREADS`), made on first use."""
    state = websocket.app.state
    limiter = getattr(state, "stream_frame_limiter", None)
    if not isinstance(limiter, anyio.CapacityLimiter):
        limiter = state.stream_frame_limiter = anyio.CapacityLimiter(FRAME_THREADS)
    return limiter


def _reason(text: str) -> str:
    """``text`` cut to fit a close frame's reason (at most 123 bytes of UTF-8)."""
    data = text.encode()
    if len(data) <= _MAX_REASON_BYTES:
        return text
    return data[: _MAX_REASON_BYTES - 3].decode(errors="ignore") + "…"


def close_code(error: Exception) -> int:
    """The close code of an error (:data:`CLOSE_CODES`; 1011 for any other exception)."""
    for cls, code in CLOSE_CODES:
        if isinstance(error, cls):
            return code
    return INTERNAL_ERROR


async def _close(websocket: WebSocket, code: int, message: str) -> None:
    """Send ``{"error": message}`` and close with ``code``; a client already gone is not an
    error."""
    with contextlib.suppress(WebSocketDisconnect, RuntimeError, OSError):
        await websocket.send_json({"error": message})
        await websocket.close(code=code, reason=_reason(message))


@router.websocket("/stream/filter")
async def stream_filter(websocket: WebSocket) -> None:
    """Filter frames as they arrive with the streaming adaptive filter.

    A browser connection from another site (its ``Origin`` not this server's scheme and host
    nor in ``cors_origins``) is refused before the handshake completes (403). The filter runs
    on a worker thread, never on the event loop; ``stream_max_keypoints``,
    ``stream_max_frame_bytes`` and ``stream_max_frames_per_s`` bound one stream's cost. A
    message the server cannot use closes the socket with a code and a reason (see the module
    notes), never with a traceback.
    """
    settings = websocket.app.state.services.settings
    if not origin_allowed(websocket.headers, settings.cors_origins, websocket.url.scheme):
        await websocket.close(code=1008, reason="cross-site connection refused")
        return
    await websocket.accept()
    max_bytes = settings.stream_max_frame_bytes
    rate = RateWindow(max(1, int(settings.stream_max_frames_per_s)), window_s=1.0)
    try:
        first = _parse(await websocket.receive(), max_bytes)
        session = await run_in_threadpool(_session, first, settings)
        await websocket.send_json(
            {
                "ready": True,
                "n_keypoints": session.n_keypoints,
                "length_unit": session.length_unit,
                "preset": session.preset,
            }
        )
        limiter = _frame_limiter(websocket)
        while True:
            received = await websocket.receive()
            if rate.admit("frames") > 0:
                raise RateLimitError(
                    f"Expected at most {settings.stream_max_frames_per_s:g} frames per second "
                    "(setting stream_max_frames_per_s), got more",
                    retry_after_s=1,
                )
            answer = await anyio.to_thread.run_sync(
                _answer, session, received, max_bytes, limiter=limiter
            )
            await websocket.send_text(answer)
    except WebSocketDisconnect:
        return
    except MocapQAError as e:
        await _close(websocket, close_code(e), str(e))
    except Exception:
        log.exception("live filter stream: internal error")
        await _close(websocket, INTERNAL_ERROR, "internal error")
