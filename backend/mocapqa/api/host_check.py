"""The ``Host`` check: a request must name this server (``allowed_hosts``), else 400.

Like Starlette's ``TrustedHostMiddleware`` (``*`` allows any host, ``*.example.org`` a
domain's), with IPv6 handled as addresses: ``Host: [::1]:8000`` and ``Host: [0:0::1]`` both
name the allowed entry ``::1`` (or ``[::1]``; entries may be written with or without
brackets), while a bracketed host that is not an IPv6 address (``[evil]``), an unbracketed
IPv6 address (``::1``, which a client must bracket) and a malformed port are refused, and so
is a request with two ``Host`` headers, allowed or not (a proxy or log in front of the server
may have read the other one). The answer is the API's error body (JSON), on HTTP requests and
WebSocket handshakes alike.
"""

from __future__ import annotations

import ipaddress
import re
from collections.abc import Sequence

from starlette.datastructures import Headers
from starlette.responses import JSONResponse
from starlette.types import ASGIApp, Receive, Scope, Send

from mocapqa.api.errors import error_body

__all__ = ["HostCheck", "host_name", "normal_host"]

_HOST = re.compile(
    r"(?:\[(?P<ipv6>[0-9A-Fa-f:.]+)\]|(?P<name>[A-Za-z0-9._~!$&'()*+,;=%-]+))(?::(?P<port>\d{0,5}))?"
)
"""A ``Host`` header: a bracketed IPv6 literal or a registered name / IPv4, and a port."""


def normal_host(entry: str) -> str:
    """An allowed-hosts entry as compared: lower case, an IPv6 address bracketed in its
    compressed form (``0:0::1`` and ``[::1]`` both become ``[::1]``), patterns unchanged."""
    text = entry.strip().lower()
    inner = text[1:-1] if text.startswith("[") and text.endswith("]") else text
    if ":" in inner:
        try:
            return f"[{ipaddress.IPv6Address(inner).compressed}]"
        except ValueError:
            return text
    return text


def host_name(header: str | None) -> str | None:
    """The host a ``Host`` header names, as :func:`normal_host` writes it; None when the
    header is missing or malformed."""
    if not header:
        return None
    match = _HOST.fullmatch(header)
    if match is None:
        return None
    if match["ipv6"] is not None:
        try:
            return f"[{ipaddress.IPv6Address(match['ipv6']).compressed}]"
        except ValueError:
            return None
    return str(match["name"]).lower()


class HostCheck:
    """ASGI middleware refusing (400) a request whose ``Host`` is not allowed, or that has
    more than one.

    Parameters
    ----------
    app : ASGI app
        The application.
    allowed_hosts : sequence of str
        Host names, IPv4 or IPv6 addresses (bracketed or not), ``*.domain`` patterns, or
        ``*`` for any.
    """

    def __init__(self, app: ASGIApp, allowed_hosts: Sequence[str]) -> None:
        for entry in allowed_hosts:
            pattern = entry.startswith("*") and entry != "*"
            if "*" in entry[1:] or (pattern and not entry.startswith("*.")):
                raise ValueError(f"Expected '*' or '*.example.org' patterns, got {entry!r}")
        self.app = app
        self.allow_any = "*" in allowed_hosts
        self.exact = {normal_host(e) for e in allowed_hosts if not e.startswith("*")}
        self.suffixes = tuple(e[1:].lower() for e in allowed_hosts if e.startswith("*."))

    def allows(self, header: str | None) -> bool:
        """Whether a ``Host`` header names an allowed host."""
        if self.allow_any:
            return True
        host = host_name(header)
        if host is None:
            return False
        return host in self.exact or (not host.startswith("[") and host.endswith(self.suffixes))

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        hosts = Headers(scope=scope).getlist("host")
        header = hosts[0] if hosts else None
        if len(hosts) > 1:
            # Which one names the server? A proxy or log in front may have read the other.
            detail = f"Expected one Host header, got {len(hosts)}"
        elif self.allows(header):
            await self.app(scope, receive, send)
            return
        else:
            shown = (header or "")[:100]
            detail = (
                f"Expected a Host header naming this server (setting allowed_hosts), got {shown!r}"
            )
        await JSONResponse(error_body("HostError", detail), status_code=400)(scope, receive, send)
