"""``mocapqa serve``: the dashboard and REST API (uvicorn)."""

from __future__ import annotations

import typer

from mocapqa.cli.app import app

__all__ = ["serve"]


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
    """
    import uvicorn

    from mocapqa.api.app import create_app
    from mocapqa.config import get_settings

    settings = get_settings()
    if workers > 0:
        settings = settings.model_copy(update={"job_workers": workers})
    if host not in ("0.0.0.0", "::", "") and host not in settings.allowed_hosts:
        # The address served on is a name clients use; others go in MOCAPQA_ALLOWED_HOSTS.
        settings = settings.model_copy(update={"allowed_hosts": [*settings.allowed_hosts, host]})
    typer.echo(f"mocapqa: data in {settings.data_dir}, dashboard at http://{host}:{port}/")
    uvicorn.run(
        create_app(settings, demo=demo),
        host=host,
        port=port,
        log_level="info",
        # A WebSocket message over the stream's limit is refused by the protocol (close 1009)
        # before it is assembled; the app checks the same limit again.
        ws_max_size=settings.stream_max_frame_bytes,
    )
