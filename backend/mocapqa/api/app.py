"""``create_app(settings)``: the FastAPI application, its services and the static frontend.

Routes live under ``/api/v1`` (OpenAPI at ``/docs``). The frontend is served from the
repository's ``frontend/`` folder when running from a checkout, else from the package's
``mocapqa/static/frontend`` copy; the Plotly bundle is served under a name that changes with
its content (:mod:`mocapqa.api.routes.plotly_bundle`), so the UI works offline.
"""

from __future__ import annotations

import logging
import re
from collections.abc import AsyncIterator, Callable, Sequence
from contextlib import AbstractAsyncContextManager, asynccontextmanager
from pathlib import Path
from typing import Any

import anyio.to_thread
from fastapi import APIRouter, Depends, FastAPI
from fastapi.middleware.gzip import GZipMiddleware
from fastapi.responses import HTMLResponse, RedirectResponse

from mocapqa import __version__
from mocapqa.api.auth import quota_key_before_body, require
from mocapqa.api.deps import Services, check_queue
from mocapqa.api.errors import install_error_handlers
from mocapqa.api.form_parts import check_form_parts
from mocapqa.api.http_guards import install_http_guards
from mocapqa.api.index_page import STATIC_URL, index_page
from mocapqa.api.query_repeats import check_json_repeats, check_query_repeats
from mocapqa.api.routes import (
    decisions,
    filters,
    health,
    limits_models,
    reviews,
    runs,
    session,
    shoots,
    stream,
    takes,
    users,
)
from mocapqa.api.routes.plotly_bundle import add_plotly_route
from mocapqa.api.static_files import CompressedStaticFiles
from mocapqa.config import Settings
from mocapqa.jobs.demo import load_demo
from mocapqa.jobs.engine import Engine
from mocapqa.jobs.runner import JobRunner
from mocapqa.render.service import RenderService
from mocapqa.store.accounts import Accounts
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository
from mocapqa.store.roles import Action
from mocapqa.store.shoots import ShootStore

__all__ = [
    "API_PREFIX",
    "VENDORED_SCRIPTS",
    "create_app",
    "frontend_dir",
    "missing_vendored_scripts",
]

API_PREFIX = "/api/v1"
"""Path prefix of every API route."""

_READ = Depends(require(Action.READ))
ROUTERS: tuple[tuple[APIRouter, Sequence[Any]], ...] = (
    (health.router, ()),
    (session.router, ()),
    (users.router, ()),
    (takes.router, (_READ,)),
    (runs.router, (_READ,)),
    (reviews.router, (_READ,)),
    (decisions.router, (_READ,)),
    (filters.router, (_READ,)),
    (stream.router, (_READ,)),
    (shoots.router, (_READ,)),
    (limits_models.router, (_READ,)),
)
"""Every router with the dependencies that guard all its routes (``Depends(...)`` items):
the one place where a router gets, for example, a sign-in requirement. Reading needs a
signed-in viewer (or a server without users); routes that change something name their own
action (``api/auth.py``'s ``require``), the account routes each theirs. A new router (shoots)
goes here with ``(_READ,)`` and its delete route calls ``require_owner``."""
log = logging.getLogger(__name__)


def frontend_dir() -> Path:
    """The folder holding ``index.html``: the checkout's ``frontend/`` or the packaged copy."""
    package = Path(__file__).resolve().parents[1]
    for candidate in (package.parents[1] / "frontend", package / "static" / "frontend"):
        if (candidate / "index.html").is_file():
            return candidate
    raise FileNotFoundError("frontend/index.html not found in the checkout or the package")


VENDORED_SCRIPTS = ("three/three.module.min.js", "three/three.core.min.js")
"""The files of ``frontend/vendor`` the dashboard cannot draw without (three.js: Plotly falls
back to the copy inside its own wheel); ``scripts/vendor_js.py`` copies them."""


def missing_vendored_scripts(frontend: Path) -> list[str]:
    """The :data:`VENDORED_SCRIPTS` missing under ``frontend / "vendor"``."""
    return [name for name in VENDORED_SCRIPTS if not (frontend / "vendor" / name).is_file()]


def _services(settings: Settings, renderer: RenderService | None) -> Services:
    """The store, files, render thread and job runner an app uses (a Dask engine when a
    scheduler is named: one take is faster on a thread here otherwise)."""
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    repository = Repository(
        settings.resolved_database_url, threads=settings.server_threads + settings.job_workers
    )
    files = FileStore(settings.data_dir)
    render_service = RenderService() if renderer is None else renderer
    engine = Engine(settings.dask_scheduler) if settings.dask_scheduler else None
    runner = JobRunner(
        repository,
        files,
        settings.job_workers,
        render_service,
        max_attempts=settings.max_run_attempts,
        read_limits=settings.read_limits,
        engine=engine,
        max_in_line=settings.max_queued_runs_per_user,
    )
    return Services(settings, repository, files, runner, render_service)


def _lifespan(
    services: Services, accounts: Accounts, demo: bool, owns_renderer: bool
) -> Callable[[FastAPI], AbstractAsyncContextManager[None]]:
    """Start: the thread limit, partial uploads swept, interrupted runs re-queued, the demo
    loaded; stop: the runner, the Dask engine, the render thread (when the app made it), the
    credentials' last uses written, the pool closed."""
    settings, repository, files, runner = (
        services.settings, services.repository, services.files, services.runner
    )  # fmt: skip

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        anyio.to_thread.current_default_thread_limiter().total_tokens = settings.server_threads
        swept = files.sweep_incoming()
        if swept:
            log.info("removed %d partial upload(s) left by a stopped server", swept)
        requeued = runner.start()
        if requeued:
            log.info("re-queued %d interrupted run(s)", len(requeued))
        if demo:
            load_demo(repository, files, runner)
        try:
            yield
        finally:
            runner.shutdown()
            if runner.engine is not None:
                runner.engine.close()
            if owns_renderer and services.renderer is not None:
                services.renderer.close()
            accounts.last_use.flush()
            repository.close()

    return lifespan


def _add_pages(app: FastAPI, plotly_url: str) -> None:
    """The dashboard's page, the take links it answers and its static files."""
    static = frontend_dir()
    page = index_page(static, plotly_url)
    static_files = CompressedStaticFiles(directory=static)
    page_files = [a.removeprefix(STATIC_URL) for a in page.modules]

    @app.get("/", include_in_schema=False)
    def index() -> HTMLResponse:
        static_files.warm(page_files)  # the first page's modules gzipped before they are asked
        return HTMLResponse(page.html, headers={"Cache-Control": "no-cache"})

    @app.get("/take/{take_id}", include_in_schema=False)
    def take_page(take_id: str) -> RedirectResponse:
        return RedirectResponse(f"/#/take/{take_id}")

    app.mount(STATIC_URL.rstrip("/"), static_files, name="static")


def create_app(
    settings: Settings, demo: bool = False, renderer: RenderService | None = None
) -> FastAPI:
    """Build the application.

    Parameters
    ----------
    settings : Settings
        Data folder, database URL, upload limit, worker count.
    demo : bool
        Load the bundled demo takes (analysed) when the database has no takes.
    renderer : RenderService, optional
        A render thread to share (the caller closes it). By default the app creates its own
        (one per app: VTK renders on one thread) and closes it on shutdown. Rendering starts
        lazily, so an app whose runs never draw pays nothing.
    """
    services = _services(settings, renderer)
    accounts = Accounts(services.repository.engine)
    app = FastAPI(
        title="mocapqa",
        version=__version__,
        description="Motion-capture QA: twist errors, joint limits and keypoint filtering.",
        lifespan=_lifespan(services, accounts, demo, owns_renderer=renderer is None),
        # Every route: a form route refuses the parts it would not read (api/form_parts.py),
        # and a query parameter or JSON key read once may be sent once (api/query_repeats.py).
        dependencies=[
            Depends(check_form_parts),
            Depends(check_query_repeats),
            Depends(check_json_repeats),
        ],
    )
    app.state.services = services
    app.state.accounts = accounts
    app.add_middleware(GZipMiddleware, minimum_size=2048, compresslevel=5)
    install_http_guards(
        app,
        settings,
        f"{API_PREFIX}/takes",
        lambda key: check_queue(services, key),
        lambda connection: quota_key_before_body(connection, accounts),
        re.compile(rf"{API_PREFIX}/shoots/([^/]+)/takes"),
        ShootStore(services.repository.engine).require,
    )
    install_error_handlers(app)
    for router, dependencies in ROUTERS:
        app.include_router(router, prefix=API_PREFIX, dependencies=list(dependencies))
    _add_pages(app, add_plotly_route(app, frontend_dir()))
    return app
