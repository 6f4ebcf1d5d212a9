"""A real uvicorn server for tests that need concurrency (``/health`` while another request
is refused) or a client outside the process (schemathesis)."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

import uvicorn

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.render.service import RenderService


def free_port() -> int:
    """A free TCP port on the loopback interface."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@contextmanager
def live_server(settings: Settings, renderer: RenderService | None = None) -> Iterator[str]:
    """Serve ``create_app(settings)`` on a free loopback port in a thread; yields the URL."""
    port = free_port()
    app = create_app(settings, renderer=renderer)
    config = uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", ws="websockets")
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 120
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            raise TimeoutError("uvicorn did not start")
        time.sleep(0.05)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        server.should_exit = True
        thread.join(timeout=60)
