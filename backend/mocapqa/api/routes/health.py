"""``GET /health``."""

from __future__ import annotations

import anyio
import anyio.to_thread
from fastapi import APIRouter, Request

from mocapqa import __version__
from mocapqa.api.deps import get_services
from mocapqa.api.errors import responses
from mocapqa.api.schemas import HealthOut

__all__ = ["router"]

router = APIRouter(tags=["health"])
"""Routes of this resource, included under ``/api/v1``."""

PING_THREADS = 2
"""Threads of the health check's own: a busy server's request threads never delay it."""


def _ping_limiter(request: Request) -> anyio.CapacityLimiter:
    limiter = getattr(request.app.state, "ping_limiter", None)
    if not isinstance(limiter, anyio.CapacityLimiter):
        limiter = request.app.state.ping_limiter = anyio.CapacityLimiter(PING_THREADS)
    return limiter


@router.get("/health", responses=responses())
async def health(request: Request) -> HealthOut:
    """The server is up and its database answers; which version and dialect it uses.

    Asked by monitors while the server is under load, so it waits for no request thread:
    the database is pinged on the check's own threads (:data:`PING_THREADS`).
    """
    services = get_services(request)
    await anyio.to_thread.run_sync(services.repository.ping, limiter=_ping_limiter(request))
    return HealthOut(version=__version__, database=services.repository.engine.dialect.name)
