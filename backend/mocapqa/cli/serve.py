"""``mocapqa serve``: the dashboard and REST API (uvicorn)."""

from __future__ import annotations

import ipaddress

import typer

from mocapqa.cli.app import app

__all__ = ["FIRST_ADMIN", "is_loopback", "require_vendored_scripts", "serve"]

FIRST_ADMIN = "admin"
"""Name of the admin ``serve`` creates on first start with an empty user table."""


def is_loopback(host: str) -> bool:
    """Whether ``host`` is reachable only from this machine."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def _sign_in(host: str, port: int) -> str | None:
    """A one-time sign-in link for the first enabled admin, printed to the server's own
    output (as Jupyter does). On a loopback address the first start on an empty store creates
    that admin; on any other address a store without users is refused."""
    from mocapqa.api.routes.session import sign_in_link
    from mocapqa.config import get_settings
    from mocapqa.errors import MocapQAError
    from mocapqa.store.accounts import Accounts
    from mocapqa.store.repository import Repository
    from mocapqa.store.roles import Role

    settings = get_settings()
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    repository = Repository(settings.resolved_database_url)
    try:
        accounts = Accounts(repository.engine)
        if not is_loopback(host) and not accounts.has_users():
            raise MocapQAError(
                f"Expected a configured user before serving on {host} (reachable from "
                "other machines), got none: create one with `mocapqa users add NAME --role "
                "admin --password`, or serve on 127.0.0.1"
            )
        admins = [u for u in accounts.list_users() if u.role is Role.ADMIN and not u.disabled]
        if not accounts.has_users():
            admins = [accounts.add_user(FIRST_ADMIN, Role.ADMIN)]
            accounts.record("user_add", None, "serve", FIRST_ADMIN, "role=admin (first start)")
        if not admins:
            return None
        shown = "127.0.0.1" if host in ("0.0.0.0", "::", "") else host
        shown = f"[{shown}]" if ":" in shown else shown
        return sign_in_link(accounts, admins[0], f"http://{shown}:{port}")
    finally:
        repository.close()


def require_vendored_scripts() -> None:
    """Refuse to serve a dashboard that cannot draw: a checkout without the vendored three.js
    (its take page failed with "Failed to fetch dynamically imported module" and drew nothing,
    while the server started without a word).

    Raises
    ------
    NotFoundError
        Naming the missing files and the command that fetches them.
    """
    from mocapqa.api.app import frontend_dir, missing_vendored_scripts
    from mocapqa.errors import NotFoundError

    folder = frontend_dir()
    missing = missing_vendored_scripts(folder)
    if missing:
        raise NotFoundError(
            f"Expected the dashboard's vendored scripts in {folder / 'vendor'}, got none of "
            f"{', '.join(missing)}: run `make js-deps` in the checkout (npm), or install a "
            "built wheel"
        )


@app.command()
def serve(
    host: str = typer.Option("127.0.0.1", help="Address to listen on."),
    port: int = typer.Option(8000, help="TCP port."),
    demo: bool = typer.Option(False, help="Load the demo takes into an empty data folder."),
    workers: int = typer.Option(0, help="Analysis worker threads (0: MOCAPQA_JOB_WORKERS)."),
) -> None:
    """Start the dashboard at http://HOST:PORT/ (API under /api/v1, OpenAPI at /docs).

    The data folder is ``MOCAPQA_DATA_DIR``; the database is SQLite there unless
    ``MOCAPQA_DATABASE_URL`` names another. Requests must name this server in their
    ``Host`` header: loopback names, the ``--host`` address, and ``MOCAPQA_ALLOWED_HOSTS``
    (a JSON list) for anything else, such as the machine's name when serving on 0.0.0.0.

    It prints a one-time sign-in link (valid 15 minutes) for an admin. On a loopback address
    the first start on an empty store creates that admin (``admin``, link and tokens only);
    serving on any other address needs a user made first (``mocapqa users add``).
    """
    import uvicorn

    from mocapqa.api.app import create_app
    from mocapqa.config import get_settings

    require_vendored_scripts()
    settings = get_settings()
    if workers > 0:
        settings = settings.model_copy(update={"job_workers": workers})
    if host not in ("0.0.0.0", "::", "") and host not in settings.allowed_hosts:
        # The address served on is a name clients use; others go in MOCAPQA_ALLOWED_HOSTS.
        settings = settings.model_copy(update={"allowed_hosts": [*settings.allowed_hosts, host]})
    link = _sign_in(host, port)
    shown = f"[{host}]" if ":" in host else host  # an IPv6 address is bracketed in a URL
    typer.echo(f"mocapqa: data in {settings.data_dir}, dashboard at http://{shown}:{port}/")
    if link:
        typer.echo(f"mocapqa: sign in (once, within 15 minutes) at {link}")
    uvicorn.run(
        create_app(settings, demo=demo),
        host=host,
        port=port,
        log_level="info",
        # A WebSocket message over the stream's limit is refused by the protocol (close 1009)
        # before it is assembled; the app checks the same limit again.
        ws_max_size=settings.stream_max_frame_bytes,
        # uvicorn believes X-Forwarded-For from 127.0.0.1 by default (FORWARDED_ALLOW_IPS):
        # any local process could then forge its address. The app reads forwarded headers
        # only from MOCAPQA_TRUSTED_PROXIES (api/http_guards.py).
        proxy_headers=False,
    )
