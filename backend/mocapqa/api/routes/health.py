"""``GET /health``."""

from __future__ import annotations

from fastapi import APIRouter

from mocapqa import __version__
from mocapqa.api.deps import ServicesDep
from mocapqa.api.errors import responses
from mocapqa.api.schemas import HealthOut

__all__ = ["router"]

router = APIRouter(tags=["health"])
"""Routes of this resource, included under ``/api/v1``."""


@router.get("/health", responses=responses())
def health(services: ServicesDep) -> HealthOut:
    """The server is up and its database answers; which version and dialect it uses."""
    services.repository.ping()
    return HealthOut(version=__version__, database=services.repository.engine.dialect.name)
