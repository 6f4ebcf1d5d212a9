"""``mocapqa bench api``: requests/s and latency per route under 1–100 parallel clients."""

from __future__ import annotations

import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from datetime import timedelta
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from mocapqa.cli.app import bench_app

if TYPE_CHECKING:
    from mocapqa_bench.api_load import Client, LoadResult, Seed, ServerProcess

__all__ = [
    "LOAD_SETTINGS",
    "bench_api",
    "fresh_server",
    "load_clients",
    "loaded_server",
    "seed_take",
]

LOAD_SETTINGS = {
    # Each simulated user uploads and runs a few takes in seconds: the per-user quotas, which
    # are there to stop one user flooding the queue, would answer 429 and measure nothing.
    "MOCAPQA_MAX_QUEUED_RUNS_PER_USER": "1000",
    "MOCAPQA_UPLOADS_PER_MINUTE_PER_USER": "1000",
}
"""Server settings of a load run."""
SEED_FILE = "cmu_12_01_walk_twist_errors.bvh"
"""The demo take read and decided on (its run has twist intervals)."""
UPLOAD_FRAMES = 60
"""Frames of the take each writing client uploads (the seed take's first ones)."""


def load_clients(
    database_url: str, count: int, writers: float = 0.5, prefix: str = "load"
) -> list[Client]:
    """Make ``count`` users (a share ``writers`` of them reviewers, the rest viewers) with a
    personal token each, and an admin named ``load_admin``; the clients, in user order."""
    from mocapqa.errors import NotFoundError
    from mocapqa.store.accounts import Accounts
    from mocapqa.store.repository import Repository
    from mocapqa.store.roles import Role
    from mocapqa_bench.api_load import Client

    repository = Repository(database_url)
    try:
        accounts = Accounts(repository.engine)
        clients = []
        for index in range(count):
            name = f"{prefix}_{index:03d}"
            writes = index < round(count * writers)
            try:
                user = accounts.get_user(name)
            except NotFoundError:
                user = accounts.add_user(name, Role.REVIEWER if writes else Role.VIEWER)
            issued = accounts.issue(user.id, "api", timedelta(hours=2), name="load")
            clients.append(Client(issued.token, user.role is Role.REVIEWER))
        return clients
    finally:
        repository.close()


def admin_token(database_url: str) -> str:
    """A personal token of the admin ``load_admin`` (made when missing)."""
    from mocapqa.errors import NotFoundError
    from mocapqa.store.accounts import Accounts
    from mocapqa.store.repository import Repository
    from mocapqa.store.roles import Role

    repository = Repository(database_url)
    try:
        accounts = Accounts(repository.engine)
        try:
            user = accounts.get_user("load_admin")
        except NotFoundError:
            user = accounts.add_user("load_admin", Role.ADMIN)
        return accounts.issue(user.id, "api", timedelta(hours=2), name="load").token
    finally:
        repository.close()


def seed_take(base: str, token: str) -> tuple[Seed, bytes]:
    """Upload the demo take with twist errors, wait for its run; the seed and the short take
    the clients upload."""
    from mocapqa.jobs.demo import demo_paths
    from mocapqa_bench.api_load import Connection, Seed, short_take, wait_until

    path = next(p for p in demo_paths() if p.name == SEED_FILE)
    http = Connection(base, token)
    try:
        _, created = http.post_file("seed", "/takes", path.name, path.read_bytes())
        if created is None:
            raise RuntimeError(f"the seed take {path.name} was refused")
        take_id, run_id = created["id"], created["run_id"]

        def finished() -> bool:
            _, run = http.request("seed", "GET", f"/runs/{run_id}")
            return run is not None and run["status"] in ("done", "failed")

        wait_until("seed run", finished)
        _, decided = http.request("seed", "GET", f"/runs/{run_id}/decisions")
        intervals = decided["intervals"] if decided else []
    finally:
        http.close()
    seed = Seed(take_id, run_id, tuple(int(i["id"]) for i in intervals))
    return seed, short_take(path.read_text(), UPLOAD_FRAMES)


@contextmanager
def loaded_server(data_dir: Path, database_url: str | None) -> Iterator[ServerProcess]:
    """A ``mocapqa serve`` child on ``data_dir`` (and ``database_url``) with
    :data:`LOAD_SETTINGS`; stopped after."""
    from mocapqa_bench.api_load import ServerProcess

    environ = dict(LOAD_SETTINGS)
    if database_url:
        environ["MOCAPQA_DATABASE_URL"] = database_url
    server = ServerProcess(data_dir, environ)
    try:
        yield server
    finally:
        server.stop()


@contextmanager
def fresh_server(database_url: str | None) -> Iterator[tuple[ServerProcess, str, str]]:
    """A server on an empty store (a new SQLite in a scratch folder, or the PostgreSQL
    database emptied), so that each measurement starts from the same state; yields the
    server, its database URL and an admin's token."""
    from mocapqa.store.upgrade import drop_database

    with tempfile.TemporaryDirectory(prefix="mocapqa-bench-api-") as scratch:
        data_dir = Path(scratch)
        if database_url:
            from sqlalchemy import create_engine

            engine = create_engine(database_url)
            try:
                drop_database(engine)
            finally:
                engine.dispose()
        url = database_url or f"sqlite:///{data_dir / 'mocapqa.sqlite3'}"
        token = admin_token(url)
        with loaded_server(data_dir, database_url) as server:
            yield server, url, token


def _table(result: LoadResult, what: str) -> object:
    from rich.table import Table

    from mocapqa_bench.api_load import route_figures

    table = Table(
        title=f"{what}: {len(result.samples)} requests in {result.seconds:.1f} s",
        title_justify="left",
    )
    columns = ("route", "requests", "req/s", "p50 ms", "p95 ms", "p99 ms", "max ms", "5xx", "4xx")
    for column in columns:
        table.add_column(column, justify="left" if column == "route" else "right")
    for row in route_figures(result):
        table.add_row(
            row.route, str(row.requests), f"{row.per_s:.1f}", f"{row.p50_ms:.1f}",
            f"{row.p95_ms:.1f}", f"{row.p99_ms:.1f}", f"{row.max_ms:.1f}",
            str(row.errors_5xx), str(row.refused_4xx),
        )  # fmt: skip
    return table


@bench_app.command("api")
def bench_api(
    clients: Annotated[
        list[int] | None, typer.Option("--clients", help="Parallel clients (repeat the option).")
    ] = None,
    rounds: Annotated[int, typer.Option(min=1, max=100, help="Rounds per client.")] = 3,
    writers: Annotated[
        float, typer.Option(min=0.0, max=1.0, help="Share of the clients that are reviewers.")
    ] = 0.5,
    think: Annotated[
        list[float] | None,
        typer.Option(
            "--think",
            min=0.0,
            max=60.0,
            help="Mean pause of a client before each request, s (repeat the option; "
            "default 1 and 0: a reviewer's pace, then back to back).",
        ),
    ] = None,
    streams: Annotated[
        int,
        typer.Option(min=0, max=500, help="Live-filter WebSocket streams at once (0: none)."),
    ] = 50,
    stream_keypoints: Annotated[
        int, typer.Option(min=1, max=1000, help="Keypoints of each stream.")
    ] = 1000,
    stream_frames: Annotated[int, typer.Option(min=1, max=10_000, help="Frames a stream.")] = 40,
    database_url: Annotated[
        str | None,
        typer.Option(
            help="Database of the server (default: a new SQLite in a scratch folder); "
            "a PostgreSQL database is emptied before each measurement."
        ),
    ] = None,
) -> None:
    """Requests/s and p50/p95/p99 latency per route of a real server (a child process on
    loopback) under parallel authenticated clients mixing reads, uploads, runs and review
    decisions; a share ``--writers`` of the users are reviewers (who write), the rest viewers."""
    import numpy as np
    from rich.console import Console

    from mocapqa_bench.api_load import run_load, run_streams
    from mocapqa_bench.api_load import stream_frames as frame_messages

    counts: Sequence[int] = clients or [1, 10, 50, 100]
    pauses: Sequence[float] = think if think is not None else [1.0, 0.0]
    console = Console()
    for pause in pauses:
        for count in counts:
            with fresh_server(database_url) as (server, url, token):
                with console.status(f"{count} client(s): seeding the demo take and its run"):
                    seed, take = seed_take(server.url, token)
                users = load_clients(url, count, writers)
                with console.status(f"{count} client(s) × {rounds} round(s), pause {pause:g} s"):
                    result = run_load(server.url, users, seed, take, rounds, pause)
            console.print(_table(result, f"{count} client(s), mean pause {pause:g} s"))
            health = [s.seconds for s in result.health]
            console.print(
                f"/health: {len(health)} checks, slowest {max(health) * 1000:.0f} ms; "
                f"5xx or no answer: {len(result.server_errors())}\n"
            )
    if streams:
        messages = frame_messages(stream_keypoints, stream_frames)
        with (
            fresh_server(database_url) as (server, _, token),
            console.status(f"{streams} live-filter streams × {stream_frames} frames"),
        ):
            result = run_streams(server.url, token, streams, messages, stream_keypoints)
        console.print(_table(result, f"{streams} live-filter streams"))
        health = [s.seconds for s in result.health]
        console.print(
            f"{streams} streams of {stream_keypoints} keypoints: "
            f"{len(result.samples) / result.seconds:.0f} frames/s; /health median "
            f"{float(np.median(health)) * 1000:.0f} ms, slowest {max(health) * 1000:.0f} ms"
        )
