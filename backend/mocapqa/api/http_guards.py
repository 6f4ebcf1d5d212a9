"""What every HTTP request passes before a route: host, origin, body size, upload rate.

One ASGI middleware (:class:`RequestGuard`), so each check answers before the body is read:

* **Origin**: a state-changing request (POST, PUT, PATCH, DELETE) that a browser marks as
  coming from another site (``Sec-Fetch-Site: cross-site``, or an ``Origin`` whose scheme and
  host are not the request's scheme and ``Host`` nor in ``cors_origins``) gets 403 — no page
  elsewhere can upload or delete through a visitor's browser. Clients that are not browsers
  send neither header.
* **Body size**: counted while it streams (Content-Length or chunked), with Starlette's
  :class:`~starlette.middleware.body_limit.RequestBodyLimitMiddleware`: the upload route allows
  ``max_upload_mb`` (plus the multipart envelope), a shoot import (many files or archives in
  one request) ``archive_max_unpacked_mb``, every other route ``max_request_kb``.
  Over the limit the request gets 413 and no more of the body is read.
* **Upload rate and queued runs per user**: an upload (or shoot import) beyond
  ``uploads_per_minute_per_user``, or from a user with ``max_queued_runs_per_user`` runs
  waiting, gets 429 with ``Retry-After`` before its body is read. The user is found from the
  request's token or session cookie alone (a hash and one query by primary key, on a worker
  thread); an anonymous request to a server without users counts against its client address.
  An upload the routes would refuse with 401 (a credential that is not valid, or none while
  users exist) gets its 401 here, before its body is read too, and one from a user whose role
  may not upload (a viewer) its 403. An import into a shoot that does not exist gets its 404
  here as well (after the 401/403, so the answer says nothing of shoots to a stranger).
* **Staging per user** (:mod:`mocapqa.jobs.staging`): an import beyond
  ``max_concurrent_imports_per_user`` in progress, or an upload or import whose announced body
  (``Content-Length``, else its body limit) would take the user's requests in progress past
  ``max_incoming_mb_per_user`` staged in ``incoming/``, gets 429 with ``Retry-After`` before
  its body is read (413 when it is over that alone). The request's hold is in its scope's
  state (:data:`STAGING_STATE`), where an import adds each archive's declared unpacked size
  before unpacking it; it is given back when the request ends.
* **Text no store can keep**: a NUL (``%00``) in the path or in a query parameter gets 422
  naming ``path`` or ``query.NAME`` (PostgreSQL refuses NUL in text; JSON bodies get the same
  check from :class:`~mocapqa.api.request_model.RequestModel`).
* **Security headers** on every answer: a Content-Security-Policy the dashboard satisfies (no
  inline script; Plotly sets inline styles), ``frame-ancestors 'none'``, ``nosniff``,
  ``Referrer-Policy: same-origin``.

The ``Host`` header is checked by :class:`~mocapqa.api.host_check.HostCheck` (IPv6 literals
compared as addresses) and CORS (off unless ``cors_origins`` is set) by Starlette's
``CORSMiddleware``; :func:`install_http_guards` adds all three.
"""

from __future__ import annotations

import json
import re
import threading
import time
from collections import deque
from collections.abc import Callable
from urllib.parse import parse_qsl, urlsplit

from fastapi import FastAPI
from starlette.concurrency import run_in_threadpool
from starlette.datastructures import Headers
from starlette.middleware.body_limit import RequestBodyLimitMiddleware
from starlette.middleware.cors import CORSMiddleware
from starlette.requests import HTTPConnection
from starlette.types import ASGIApp, Message, Receive, Scope, Send
from uvicorn.middleware.proxy_headers import ProxyHeadersMiddleware

from mocapqa.api.errors import error_body
from mocapqa.api.host_check import HostCheck
from mocapqa.api.request_model import unstorable_text
from mocapqa.config import Settings
from mocapqa.errors import ForbiddenError, NotFoundError, RateLimitError, TooLargeError
from mocapqa.jobs.staging import StagingHold, StagingQuota

__all__ = [
    "CONTENT_SECURITY_POLICY",
    "MULTIPART_SLACK_BYTES",
    "STAGING_STATE",
    "RateWindow",
    "RequestGuard",
    "install_http_guards",
    "origin_allowed",
    "unstorable_location",
]

CONTENT_SECURITY_POLICY = (
    "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
    "img-src 'self' data: blob:; connect-src 'self'; font-src 'self'; object-src 'none'; "
    "base-uri 'none'; form-action 'self'; frame-ancestors 'none'"
)
"""The dashboard's policy: its scripts are files of this server; Plotly styles inline."""
_DOCS_POLICY = (
    "default-src 'self'; script-src 'self' 'unsafe-inline' https://cdn.jsdelivr.net; "
    "style-src 'self' 'unsafe-inline' https://cdn.jsdelivr.net; "
    "img-src 'self' data: https://fastapi.tiangolo.com; frame-ancestors 'none'"
)
_DOCS_PATHS = ("/docs", "/redoc")
MULTIPART_SLACK_BYTES = 64_000
"""Allowance for the multipart envelope around an upload's file."""
_STATE_CHANGING = frozenset({"POST", "PUT", "PATCH", "DELETE"})
STAGING_STATE = "staging_hold"
"""Name, in an upload's request state, of its :class:`~mocapqa.jobs.staging.StagingHold`."""


def origin_allowed(headers: Headers, cors_origins: list[str], scheme: str) -> bool:
    """Whether a browser request comes from this site (or an allowed one).

    ``Sec-Fetch-Site: cross-site`` is refused unless its ``Origin`` is in ``cors_origins``;
    an ``Origin`` must name the request's own scheme (``scheme``: the request's, ``ws`` and
    ``wss`` standing for ``http`` and ``https``) and ``Host``, or be listed: a page on
    ``https://host`` is another site to ``http://host``. No header at all (a script, the CLI,
    curl) is allowed.
    """
    origin = headers.get("origin")
    if origin and origin in cors_origins:
        return True
    if headers.get("sec-fetch-site") == "cross-site":
        return False
    if origin is None:
        return True
    if origin == "null":
        return False
    parts = urlsplit(origin)
    own = {"ws": "http", "wss": "https"}.get(scheme.lower(), scheme.lower())
    return parts.scheme.lower() == own and parts.netloc.lower() == headers.get("host", "").lower()


def unstorable_location(scope: Scope) -> tuple[str, str] | None:
    """Where a request's path or query holds text no store can keep (``path`` or
    ``query.NAME``) and why, or None (see :func:`~mocapqa.api.request_model.unstorable_text`)."""
    problem = unstorable_text(scope["path"])
    if problem is not None:
        return "path", problem
    query = scope.get("query_string", b"").decode("latin-1")
    for name, value in parse_qsl(query, keep_blank_values=True):
        problem = unstorable_text(name) or unstorable_text(value)
        if problem is not None:
            return f"query.{name}", problem
    return None


class RateWindow:
    """Events per key (a user, or an address) in a sliding window (thread-safe).

    Parameters
    ----------
    limit : int
        Events allowed per window.
    window_s : float
        Window length, seconds.
    clock : callable
        Monotonic seconds (tests pass their own).
    """

    def __init__(
        self, limit: int, window_s: float = 60.0, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.limit = limit
        self.window_s = window_s
        self._clock = clock
        self._events: dict[str, deque[float]] = {}
        self._lock = threading.Lock()

    def admit(self, key: str) -> float:
        """Record an event for ``key``; 0 when admitted, else seconds until one would be."""
        now = self._clock()
        with self._lock:
            events = self._events.setdefault(key, deque())
            while events and events[0] <= now - self.window_s:
                events.popleft()
            if len(events) >= self.limit:
                return events[0] + self.window_s - now
            events.append(now)
            if len(self._events) > 10_000:  # forget idle keys
                for idle in [k for k, v in self._events.items() if not v]:
                    del self._events[idle]
            return 0.0


async def _send_json(
    send: Send,
    status: int,
    body: dict[str, object],
    retry: int = 0,
    extra: list[tuple[bytes, bytes]] | None = None,
) -> None:
    data = json.dumps(body).encode()
    headers = [(b"content-type", b"application/json"), (b"content-length", b"%d" % len(data))]
    headers += extra or []
    if retry:
        headers.append((b"retry-after", str(retry).encode()))
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": data})


class RequestGuard:
    """The origin, body-size, upload-rate and header checks (see the module notes)."""

    def __init__(
        self,
        app: ASGIApp,
        settings: Settings,
        upload_path: str,
        check_queue: Callable[[str], None],
        quota_key: Callable[[HTTPConnection], str | None],
        import_paths: re.Pattern[str] | None = None,
        import_target: Callable[[str], None] | None = None,
    ) -> None:
        self.app = app
        self.import_target = import_target
        self.quota_key = quota_key
        self.settings = settings
        self.upload_path = upload_path
        self.import_paths = import_paths
        self.import_bytes = int(settings.archive_max_unpacked_mb * 1_000_000)
        self.check_queue = check_queue
        self.uploads = RateWindow(settings.uploads_per_minute_per_user)
        self.upload_bytes = int(settings.max_upload_mb * 1_000_000) + MULTIPART_SLACK_BYTES
        self.request_bytes = int(settings.max_request_kb * 1000)
        self.staging = StagingQuota(
            settings.max_concurrent_imports_per_user,
            int(settings.max_incoming_mb_per_user * 1_000_000),
        )

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = Headers(scope=scope)
        method = scope["method"]
        imported = (
            self.import_paths.fullmatch(scope["path"])
            if method == "POST" and self.import_paths is not None
            else None
        )
        is_import = imported is not None
        is_upload = (method == "POST" and scope["path"] == self.upload_path) or is_import
        secured = self._with_headers(send, scope["path"].startswith(_DOCS_PATHS), is_upload)
        if method in _STATE_CHANGING and not origin_allowed(
            headers, self.settings.cors_origins, scope.get("scheme", "http")
        ):
            detail = (
                f"Expected a request from this site, got Origin {headers.get('origin')!r}, "
                f"Sec-Fetch-Site {headers.get('sec-fetch-site')!r}"
            )
            await _send_json(secured, 403, error_body("ForbiddenError", detail))
            return
        unstorable = unstorable_location(scope)
        if unstorable is not None:
            field, message = unstorable
            entry = {"field": field, "message": message}
            body = error_body("ValidationError", f"{field}: {message}", field=field, errors=[entry])
            await _send_json(secured, 422, body)
            return
        hold: StagingHold | None = None
        if is_upload:
            try:
                key = await run_in_threadpool(self.quota_key, HTTPConnection(scope))
            except ForbiddenError as e:
                await _send_json(secured, 403, error_body("ForbiddenError", str(e)))
                return
            if key is None:
                detail = "Expected a signed-in user (a valid session cookie or 'Authorization: "
                detail += "Bearer TOKEN') to upload, got none or an invalid one"
                body = error_body("AuthenticationError", detail)
                await _send_json(secured, 401, body, extra=[(b"www-authenticate", b"Bearer")])
                return
            if imported is not None and imported.groups() and self.import_target is not None:
                try:
                    await run_in_threadpool(self.import_target, imported.group(1))
                except NotFoundError as e:
                    await _send_json(secured, 404, error_body("NotFoundError", str(e)))
                    return
            try:
                hold = self._staging_hold(key, headers, is_import)
            except (RateLimitError, TooLargeError) as e:
                retry = e.retry_after_s if isinstance(e, RateLimitError) else 0
                body = error_body(type(e).__name__, str(e))
                await _send_json(secured, 429 if retry else 413, body, retry)
                return
            refused = self._upload_refusal(key)
            if refused is not None:
                hold.close()
                await _send_json(secured, 429, refused[0], refused[1])
                return
        limit = self.upload_bytes if is_upload else self.request_bytes
        if is_import:
            limit = self.import_bytes
        if hold is None:
            await RequestBodyLimitMiddleware(self.app, limit)(scope, receive, secured)
            return
        scope["state"] = {**scope.get("state", {}), STAGING_STATE: hold}
        try:
            await RequestBodyLimitMiddleware(self.app, limit)(scope, receive, secured)
        finally:
            hold.close()

    def _staging_hold(self, key: str, headers: Headers, is_import: bool) -> StagingHold:
        """Admit an upload's announced body (its Content-Length, else its body limit) to its
        user's staging allowance; raises what :meth:`StagingQuota.admit` raises."""
        limit = self.import_bytes if is_import else self.upload_bytes
        length = headers.get("content-length", "")
        announced = int(length) if length.isascii() and length.isdigit() else limit
        return self.staging.admit(key, min(announced, limit), is_import)

    def _upload_refusal(self, key: str) -> tuple[dict[str, object], int] | None:
        try:
            self.check_queue(key)
        except RateLimitError as full:
            return error_body("RateLimitError", str(full)), full.retry_after_s
        wait = self.uploads.admit(key)
        if wait > 0:
            per_minute = self.settings.uploads_per_minute_per_user
            detail = f"Expected at most {per_minute} uploads per minute per user (setting "
            detail += "uploads_per_minute_per_user), got more"
            return error_body("RateLimitError", detail), int(wait) + 1
        return None

    def _with_headers(self, send: Send, docs: bool, upload: bool = False) -> Send:
        policy = (_DOCS_POLICY if docs else CONTENT_SECURITY_POLICY).encode()
        rewrite = [False]
        if upload:
            limit = int(self.settings.max_upload_mb * 1_000_000)
            detail = f"Expected an upload of at most {limit} bytes (setting max_upload_mb)"
        else:
            detail = f"Expected a request body of at most {self.request_bytes} bytes "
            detail += "(setting max_request_kb)"
        too_large = json.dumps(error_body("TooLargeError", f"{detail}, got more")).encode()

        async def secured(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = list(message.get("headers", []))
                if (
                    message["status"] == 413
                    and (b"content-type", b"text/plain; charset=utf-8") in headers
                ):
                    # Starlette's body limit answers in plain text: give it the error shape.
                    rewrite[0] = True
                    headers = [
                        (b"content-type", b"application/json"),
                        (b"content-length", str(len(too_large)).encode()),
                    ]
                extra = [
                    (b"content-security-policy", policy),
                    (b"x-content-type-options", b"nosniff"),
                    (b"x-frame-options", b"DENY"),
                    (b"referrer-policy", b"same-origin"),
                ]
                message = {**message, "headers": [*headers, *extra]}
            elif message["type"] == "http.response.body" and rewrite[0]:
                message = {**message, "body": too_large, "more_body": False}
            await send(message)

        return secured


def install_http_guards(
    app: FastAPI,
    settings: Settings,
    upload_path: str,
    check_queue: Callable[[str], None],
    quota_key: Callable[[HTTPConnection], str | None],
    import_paths: re.Pattern[str] | None = None,
    import_target: Callable[[str], None] | None = None,
) -> None:
    """Add the request guard, CORS (when ``cors_origins`` is set), the Host check and, for
    ``trusted_proxies``, uvicorn's forwarded-header middleware, in the order that makes the
    forwarded headers apply first, then the Host check. ``check_queue`` refuses a quota key
    whose run queue is full (raising :class:`~mocapqa.errors.RateLimitError`, answered 429
    before the upload's body is read), ``quota_key`` names a request's key from its headers,
    None for a request to refuse with 401 (a blocking call: it runs on a worker thread);
    ``import_paths`` matches the
    routes that take many files in one request (uploads with the import body limit), its
    first group the target's id, which ``import_target`` (blocking) checks, raising
    :class:`~mocapqa.errors.NotFoundError` (answered 404) when it does not exist.
    ``quota_key`` raises :class:`~mocapqa.errors.ForbiddenError` for a user whose role may not
    upload (answered 403)."""
    app.add_middleware(
        RequestGuard,
        settings=settings,
        upload_path=upload_path,
        check_queue=check_queue,
        quota_key=quota_key,
        import_paths=import_paths,
        import_target=import_target,
    )
    if settings.cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=settings.cors_origins,
            allow_methods=["GET", "POST", "PATCH", "DELETE"],
            allow_headers=["Content-Type", "Authorization"],
            max_age=600,
        )
    app.add_middleware(HostCheck, allowed_hosts=settings.allowed_hosts)
    if settings.trusted_proxies:
        # Outermost: the address and scheme every guard, limit and audit entry sees are the
        # ones a trusted proxy vouches for; nobody else's headers are read.
        app.add_middleware(ProxyHeadersMiddleware, trusted_hosts=settings.trusted_proxies)
