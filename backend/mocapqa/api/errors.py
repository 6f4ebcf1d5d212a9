"""The one table from :mod:`mocapqa.errors` classes to HTTP status codes, and its handler.

The body is ``{"detail": message, "error": class name}`` plus ``line``/``field`` for parse
errors, so the UI can show the file's line.
"""

from __future__ import annotations

from fastapi import FastAPI, Request
from fastapi.responses import JSONResponse

from mocapqa.errors import (
    ConflictError,
    FormatError,
    InputError,
    LimitsFileError,
    MocapQAError,
    NotFoundError,
    ParseError,
    TooLargeError,
    UnsupportedFormatError,
)

__all__ = ["STATUS_CODES", "install_error_handlers", "status_for"]

# Most specific class first: the first match wins.
STATUS_CODES: tuple[tuple[type[MocapQAError], int], ...] = (
    (TooLargeError, 413),
    (UnsupportedFormatError, 415),
    (FormatError, 415),
    (LimitsFileError, 422),
    (ParseError, 422),
    (InputError, 422),
    (NotFoundError, 404),
    (ConflictError, 409),
    (MocapQAError, 400),
)


def status_for(error: MocapQAError) -> int:
    """HTTP status for an error, from :data:`STATUS_CODES`."""
    for cls, status in STATUS_CODES:
        if isinstance(error, cls):
            return status
    return 400


async def _handle(request: Request, error: Exception) -> JSONResponse:
    del request
    if not isinstance(error, MocapQAError):  # pragma: no cover - registered for MocapQAError
        raise error
    body: dict[str, object] = {"detail": str(error), "error": type(error).__name__}
    if isinstance(error, ParseError):
        body.update(line=error.line, field=error.field, message=error.message)
    return JSONResponse(body, status_code=status_for(error))


def install_error_handlers(app: FastAPI) -> None:
    """Register the handler for every :class:`MocapQAError`."""
    app.add_exception_handler(MocapQAError, _handle)
