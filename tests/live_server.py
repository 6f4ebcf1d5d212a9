"""A real uvicorn server in a thread, for every test that needs one: the browser tests, the
hostile-input suite (``/health`` while another request is refused), schemathesis (a client
outside the process) and the crash test's free port."""

from __future__ import annotations

import json
import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import uvicorn
from fastapi import FastAPI

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.render.service import RenderService

START_BOUND_S = 120.0
"""Generous bound on the server's start (a loaded 2-core machine)."""


def free_port() -> int:
    """A free TCP port on the loopback interface."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@contextmanager
def serve(app: FastAPI) -> Iterator[str]:
    """Serve ``app`` on a free loopback port in a thread; yields its URL, stops it after."""
    port = free_port()
    # As `mocapqa serve` runs it: forwarded headers only from configured proxies (the app).
    config = uvicorn.Config(
        app, host="127.0.0.1", port=port, log_level="warning", ws="websockets", proxy_headers=False
    )
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + START_BOUND_S
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            raise TimeoutError("uvicorn did not start")
        time.sleep(0.05)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        server.should_exit = True
        thread.join(timeout=60)


@contextmanager
def live_server(settings: Settings, renderer: RenderService | None = None) -> Iterator[str]:
    """Serve ``create_app(settings)`` (see :func:`serve`); yields the URL."""
    with serve(create_app(settings, renderer=renderer)) as url:
        yield url


def read_answer(sock: socket.socket) -> tuple[int, dict[str, str], Any]:
    """Read an HTTP answer with a JSON body from a socket a raw request was sent on: its
    status, headers (lower-case names) and parsed body (the server closes or the JSON ends)."""
    data = b""
    while b"\r\n\r\n" not in data or not data.rstrip().endswith(b"}"):
        chunk = sock.recv(65536)
        if not chunk:
            break
        data += chunk
    start, _, rest = data.partition(b"\r\n\r\n")
    lines = start.decode("latin-1").split("\r\n")
    headers = dict(line.lower().split(": ", 1) for line in lines[1:])
    return int(lines[0].split(" ", 2)[1]), headers, json.loads(rest)
