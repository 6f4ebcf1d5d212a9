"""Typed dependencies: the services held on ``app.state``, and repeated lookups."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Annotated, Any

from fastapi import Depends, Request

from mocapqa.api.app_state import app_state
from mocapqa.api.auth import PrincipalDep, client_address, quota_key
from mocapqa.config import Settings
from mocapqa.errors import RateLimitError
from mocapqa.jobs.runner import JobRunner
from mocapqa.render.service import RenderService
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository

__all__ = [
    "ClientDep",
    "Services",
    "ServicesDep",
    "TakeDep",
    "check_queue",
    "get_client",
    "get_services",
    "get_take",
    "run_places",
]


@dataclass(frozen=True, slots=True)
class Services:
    """What the routes use: settings, repository, files, the job runner and the render thread."""

    settings: Settings
    repository: Repository
    files: FileStore
    runner: JobRunner
    renderer: RenderService | None = None


def get_services(request: Request) -> Services:
    """The app's services."""
    return app_state(request, "services", Services)


ServicesDep = Annotated[Services, Depends(get_services)]
"""Route parameter type that receives the app's :class:`Services`."""


def get_take(take_id: str, services: ServicesDep) -> dict[str, Any]:
    """The take named in the path (404 when missing)."""
    return services.repository.get_take(take_id)


TakeDep = Annotated[dict[str, Any], Depends(get_take)]
"""Route parameter type that receives the take row named by ``take_id`` (404 when missing)."""


def get_client(request: Request, principal: PrincipalDep) -> str:
    """Who is asking, for quotas and fair scheduling: the signed-in user, else (a server
    without users) the client's address (:func:`~mocapqa.api.auth.quota_key`)."""
    return quota_key(principal.user_id, client_address(request))


ClientDep = Annotated[str, Depends(get_client)]
"""Route parameter type that receives the client's key."""


@contextmanager
def run_places(services: Services, client: str, wanted: int = 1) -> Iterator[int]:
    """Hold up to ``wanted`` of the client's free places in the run queue while the block
    records and submits its runs (:meth:`JobRunner.places`); yields how many it got, at least
    one: none free is refused (429) for a user with ``max_queued_runs_per_user`` waiting. The
    one check of the queued-run limit: the routes that start runs and the request guard
    (:func:`check_queue`) both refuse here.

    Raises
    ------
    RateLimitError
    """
    limit = services.settings.max_queued_runs_per_user
    with services.runner.places(client, wanted, limit) as granted:
        if granted == 0:
            raise RateLimitError(
                f"Expected at most {limit} queued runs per user (setting "
                "max_queued_runs_per_user), got that many waiting",
                retry_after_s=10,
            )
        yield granted


def check_queue(services: Services, client: str) -> None:
    """Refuse (429) a client whose run queue is full, as :func:`run_places` does, holding no
    place: the request guard's check before an upload's body is read.

    Raises
    ------
    RateLimitError
    """
    with run_places(services, client):
        pass
