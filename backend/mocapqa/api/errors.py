"""The one table from :mod:`mocapqa.errors` classes to HTTP status codes, and its handlers.

Every error answer has one shape, :class:`~mocapqa.api.schemas.ErrorOut`:
``{"detail": message, "error": class name}`` plus ``line``/``field`` for parse errors (so the
UI can show the file's line) and ``field``/``errors`` for request validation. FastAPI's own
validation errors and HTTP exceptions (unknown route, 405, 413 of the body limit) are turned
into the same shape; a JSON body FastAPI could not decode (not UTF-8, nested too deep) is a 422
naming ``body`` and why, a multipart body the parser refused (Starlette's bare 400) or a form
sent where JSON is read a 422 naming the field (:mod:`mocapqa.api.form_parts`).
:func:`responses` gives a route's OpenAPI ``responses=`` from the same table, so the
documented statuses are the ones the handlers answer.
"""

from __future__ import annotations

from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException
from starlette.routing import compile_path

from mocapqa.api.form_parts import form_sent_for_json, multipart_refusal
from mocapqa.api.schemas import ErrorOut
from mocapqa.errors import (
    AuthenticationError,
    ClusterError,
    ConflictError,
    ForbiddenError,
    FormatError,
    InputError,
    LimitsFileError,
    MocapQAError,
    NotFoundError,
    OptionError,
    ParseError,
    RateLimitError,
    TooLargeError,
    UnsupportedFormatError,
)

__all__ = [
    "STATUS_CODES",
    "STATUS_MEANING",
    "error_body",
    "install_error_handlers",
    "responses",
    "status_for",
]

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
    (ForbiddenError, 403),
    (AuthenticationError, 401),
    (RateLimitError, 429),
    (ClusterError, 503),
    (MocapQAError, 400),
)

STATUS_MEANING: dict[int, str] = {
    400: "Bad request (the Host header is not allowed, or another client error)",
    401: "Not signed in: no valid session cookie or Bearer token while the server has users",
    403: "Refused: a state-changing request from another site or without the session's CSRF "
    "token, or a role (or owner) that may not do this",
    404: "Not found: the take or run does not exist",
    409: "Conflict: the run is not finished, or has no twist intervals (a keypoint take)",
    413: "Too large: the body or the take exceeds a limit (named in the detail)",
    415: "Unsupported media: the file's format is not recognised",
    422: "Invalid: a parameter, an option or the file's content (field or line named)",
    429: "Too many requests from this client (see Retry-After)",
    503: "Unavailable: the Dask scheduler cannot be reached",
}
"""What each error status means, for the OpenAPI ``responses`` of every route."""


def status_for(error: MocapQAError) -> int:
    """HTTP status for an error, from :data:`STATUS_CODES`."""
    for cls, status in STATUS_CODES:
        if isinstance(error, cls):
            return status
    return 400


def responses(*statuses: int) -> dict[int | str, dict[str, Any]]:
    """The OpenAPI ``responses=`` of a route answering these error statuses (and 400/422,
    which every route may answer: a refused Host header, a malformed parameter)."""
    wanted = sorted({400, 422, *statuses})
    answers: dict[int | str, dict[str, Any]] = {
        s: {"model": ErrorOut, "description": STATUS_MEANING[s]} for s in wanted
    }
    if 401 in answers:
        answers[401]["headers"] = {
            "WWW-Authenticate": {"schema": {"type": "string"}, "description": "Bearer"}
        }
    return answers


def error_body(error: str, detail: str, **extra: Any) -> dict[str, Any]:
    """An :class:`ErrorOut` body as a dict (for middleware answering before the routes)."""
    return ErrorOut(error=error, detail=detail, **extra).model_dump(exclude_none=True)


async def _handle(request: Request, error: Exception) -> JSONResponse:
    del request
    if not isinstance(error, MocapQAError):  # pragma: no cover - registered for MocapQAError
        raise error
    extra: dict[str, Any] = {}
    if isinstance(error, ParseError):
        extra.update(line=error.line, field=error.field, message=error.message)
    if isinstance(error, OptionError):
        extra.update(field=error.field, message=error.message)
    headers = None
    if isinstance(error, RateLimitError):
        headers = {"Retry-After": str(error.retry_after_s)}
    if isinstance(error, AuthenticationError):
        headers = {"WWW-Authenticate": "Bearer"}
    body = error_body(type(error).__name__, str(error), **extra)
    return JSONResponse(body, status_code=status_for(error), headers=headers)


def _allowed_methods(request: Request) -> list[str]:
    """Every method the OpenAPI documents at this path (Starlette's 405 names only the first
    route that matched the path)."""
    methods: set[str] = set()
    for template, operations in request.app.openapi()["paths"].items():
        if compile_path(template)[0].match(request.url.path):
            methods |= {m.upper() for m in operations}
    return sorted(methods)


def _undecodable_body(error: HTTPException) -> str | None:
    """Why FastAPI could not decode a JSON body (its 400 names no reason), or None."""
    cause = error.__cause__
    if error.status_code != 400:
        return None
    if isinstance(cause, UnicodeDecodeError):
        return f"Expected a UTF-8 JSON body, got an undecodable byte at offset {cause.start}"
    if isinstance(cause, RecursionError):
        return "Expected a JSON body nested a few levels deep, got one nested too deep to parse"
    return None


def _invalid(entries: list[dict[str, str]]) -> JSONResponse:
    """The 422 of request validation: the first entry's field and message, every entry."""
    first = entries[0] if entries else {"field": "", "message": "invalid request"}
    body = error_body(
        "ValidationError",
        f"{first['field']}: {first['message']}",
        field=first["field"],
        errors=entries[:20],
    )
    return JSONResponse(body, status_code=422)


async def _handle_http(request: Request, error: Exception) -> JSONResponse:
    if not isinstance(error, HTTPException):  # pragma: no cover - registered for HTTPException
        raise error
    undecodable = _undecodable_body(error)
    if undecodable is not None:
        return _invalid([{"field": "body", "message": undecodable}])
    refused = multipart_refusal(error, request.scope.get("route"))
    if refused is not None:
        return _invalid([{"field": refused[0], "message": refused[1]}])
    body = error_body("HTTPError", str(error.detail))
    limit = request.scope.get("starlette.max_body_size")
    if error.status_code == 413 and isinstance(limit, int):
        # The body limit caught a body sent without a length (chunked) while it was read:
        # answer as a Content-Length over the limit is answered, naming the limit.
        body = error_body(
            "TooLargeError",
            f"Expected a request body of at most {limit} bytes (settings max_upload_mb, "
            "max_request_kb), got more",
        )
    headers = dict(error.headers or {})
    if error.status_code == 405:
        headers["Allow"] = ", ".join(_allowed_methods(request)) or headers.get("Allow", "")
    return JSONResponse(body, status_code=error.status_code, headers=headers or None)


def _location(entry: dict[str, Any]) -> str:
    return ".".join(str(part) for part in entry.get("loc", ()))


async def _handle_validation(request: Request, error: Exception) -> JSONResponse:
    if not isinstance(error, RequestValidationError):  # pragma: no cover - registered for it
        raise error
    entries = [
        {"field": _location(e), "message": str(e.get("msg", ""))} for e in error.errors()[:20]
    ]
    if any(entry["field"] == "body" for entry in entries):
        form = await form_sent_for_json(request)
        if form:
            return _invalid([{"field": field, "message": message} for field, message in form])
    return _invalid(entries)


def install_error_handlers(app: FastAPI) -> None:
    """Register the handlers for :class:`MocapQAError`, HTTP exceptions and validation."""
    app.add_exception_handler(MocapQAError, _handle)
    app.add_exception_handler(HTTPException, _handle_http)
    app.add_exception_handler(RequestValidationError, _handle_validation)
