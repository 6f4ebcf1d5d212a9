"""Parallel authenticated clients against a real server: what a team reviewing a shoot does.

Each client is a thread with its own keep-alive HTTP connection and its own user's token. A
round of a client reads (who am I, the take list, a take, a run, its decisions) and, for a
reviewer, writes (uploads a take, starts a run, records a review and an interval decision).
A separate thread asks ``/health`` all the while. Every request is timed and kept, so the
same run answers "any 5xx?", "how slow was /health?", "was every accepted upload stored?"
and the latency percentiles per route.

The server is a child process (``mocapqa serve``), so the clients' Python does not share a
GIL with it; only loopback addresses are ever asked.
"""

from __future__ import annotations

import http.client
import json
import os
import socket
import subprocess
import sys
import threading
import time
import urllib.request
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import numpy as np

__all__ = [
    "API",
    "START_BOUND_S",
    "Client",
    "Connection",
    "LoadResult",
    "RouteFigures",
    "Sample",
    "Seed",
    "ServerProcess",
    "free_port",
    "route_figures",
    "run_load",
    "run_streams",
    "short_take",
    "stream_frames",
    "wait_until",
]

API = "/api/v1"
"""The API's path prefix."""
START_BOUND_S = 180.0
"""Generous bound on the server's start and on a seed run (a loaded 2-core machine)."""
REQUEST_TIMEOUT_S = 120.0
"""A client gives up on one request after this long (counted as a failure, status 0)."""


@dataclass(frozen=True, slots=True)
class Client:
    """One simulated user: a bearer token, and whether the user may write (a reviewer)."""

    token: str
    writes: bool


@dataclass(frozen=True, slots=True)
class Seed:
    """What the clients read and decide on: a take, its finished run and the run's twist
    interval ids."""

    take_id: str
    run_id: str
    interval_ids: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class Sample:
    """One request: its route (method and path template), status (0: no answer), seconds,
    and the id of what it created (an upload's take id, a decision's id) if any."""

    route: str
    status: int
    seconds: float
    created: str | None = None


@dataclass(slots=True)
class LoadResult:
    """Every request of a load run, the health checks, and the wall-clock time it took."""

    clients: int
    samples: list[Sample] = field(default_factory=list)
    health: list[Sample] = field(default_factory=list)
    seconds: float = 0.0

    def server_errors(self) -> list[Sample]:
        """Requests answered 5xx or not at all, health checks included."""
        return [s for s in [*self.samples, *self.health] if s.status == 0 or s.status >= 500]

    def created(self, route: str) -> list[str]:
        """Ids created by the accepted (2xx) requests of ``route``."""
        return [
            s.created for s in self.samples if s.route == route and s.created and s.status < 300
        ]


@dataclass(frozen=True, slots=True)
class RouteFigures:
    """Throughput and latency of one route in a load run (seconds → ms in the table)."""

    route: str
    requests: int
    per_s: float
    p50_ms: float
    p95_ms: float
    p99_ms: float
    max_ms: float
    errors_5xx: int
    refused_4xx: int


def free_port() -> int:
    """A free TCP port on the loopback interface."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def wait_until(what: str, check: Callable[[], bool], bound_s: float = START_BOUND_S) -> None:
    """Call ``check`` until it is true (connection errors count as false), at most
    ``bound_s`` (a generous bound, not a deadline a test measures).

    Raises
    ------
    TimeoutError
    """
    deadline = time.monotonic() + bound_s
    while time.monotonic() < deadline:
        try:
            if check():
                return
        except (OSError, http.client.HTTPException):
            pass
        time.sleep(0.05)
    raise TimeoutError(f"{what}: not within {bound_s} s")


class ServerProcess:
    """``mocapqa serve`` as a child process on loopback.

    Parameters
    ----------
    data_dir : Path
        The server's data folder.
    environ : mapping
        ``MOCAPQA_*`` settings for the server (the database URL, quotas, worker count), and
        any other variable to set.
    command : sequence of str, optional
        The ``serve`` command line without ``--port`` (default: this Python's mocapqa).
    cwd : Path, optional
        The server's working folder.
    """

    def __init__(
        self,
        data_dir: Path,
        environ: Mapping[str, str],
        command: Sequence[str] | None = None,
        cwd: Path | None = None,
    ) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.log_path = data_dir / "server.log"
        data_dir.mkdir(parents=True, exist_ok=True)
        env = {k: v for k, v in os.environ.items() if not k.startswith("MOCAPQA_")}
        env.update({"MOCAPQA_DATA_DIR": str(data_dir), "PYTHONUNBUFFERED": "1", **environ})
        serve = list(command or [sys.executable, "-m", "mocapqa.cli.main", "serve"])
        with self.log_path.open("wb") as log:
            self.process = subprocess.Popen(
                [*serve, "--port", str(self.port)], env=env, stdout=log, stderr=log, cwd=cwd
            )
        wait_until(
            "server start",
            lambda: self.process.poll() is None and _answers(f"{self.url}{API}/health"),
        )

    def log(self) -> str:
        """What the server wrote (its access log and any traceback)."""
        return self.log_path.read_text(errors="replace")

    def stop(self) -> None:
        """SIGTERM, then wait for the server to finish its shutdown."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=120)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=60)


def _answers(url: str) -> bool:
    """Whether a GET of ``url`` answers 200."""
    with urllib.request.urlopen(url, timeout=10) as response:
        return bool(response.status == 200)


def short_take(bvh_text: str, frames: int) -> bytes:
    """The first ``frames`` frames of a BVH text (a small upload of a real take)."""
    head, _, motion = bvh_text.partition("MOTION")
    lines = [line for line in motion.strip().splitlines() if line.strip()]
    rows = lines[2 : 2 + frames]
    text = f"{head}MOTION\nFrames: {len(rows)}\n{lines[1]}\n" + "\n".join(rows) + "\n"
    return text.encode()


class Connection:
    """One keep-alive HTTP/1.1 connection of the standard library's, with a bearer token (a
    tenth of an httpx client's CPU per request: the clients share the machine with the server
    they measure)."""

    def __init__(self, base: str, token: str | None) -> None:
        parsed = urlsplit(base)
        self.host, self.port = parsed.hostname or "127.0.0.1", parsed.port or 80
        self.headers = {"Authorization": f"Bearer {token}"} if token else {}
        self.http = http.client.HTTPConnection(self.host, self.port, timeout=REQUEST_TIMEOUT_S)

    def request(
        self, route: str, method: str, path: str, body: bytes | None = None, kind: str = ""
    ) -> tuple[Sample, Any]:
        """Send one request; its :class:`Sample` and its JSON answer (None when not 2xx)."""
        headers = dict(self.headers)
        if body is not None:
            headers["Content-Type"] = kind
        start = time.perf_counter()
        try:
            self.http.request(method, API + path, body=body, headers=headers)
            response = self.http.getresponse()
            data = response.read()
        except (OSError, http.client.HTTPException):
            self.http.close()  # a new connection for the next request
            return Sample(route, 0, time.perf_counter() - start), None
        sample = Sample(route, response.status, time.perf_counter() - start)
        if response.status >= 300:
            return sample, None
        return sample, json.loads(data) if data else None

    def post_json(self, route: str, path: str, body: dict[str, Any]) -> tuple[Sample, Any]:
        """POST a JSON body."""
        return self.request(route, "POST", path, json.dumps(body).encode(), "application/json")

    def post_file(self, route: str, path: str, name: str, content: bytes) -> tuple[Sample, Any]:
        """POST one file as the multipart field ``file``."""
        boundary = uuid.uuid4().hex
        body = b"".join(
            (
                f'--{boundary}\r\nContent-Disposition: form-data; name="file"; '
                f'filename="{name}"\r\nContent-Type: application/octet-stream\r\n\r\n'.encode(),
                content,
                f"\r\n--{boundary}--\r\n".encode(),
            )
        )
        return self.request(route, "POST", path, body, f"multipart/form-data; boundary={boundary}")

    def close(self) -> None:
        """Close the connection."""
        self.http.close()


def _created(sample: Sample, answer: Any, key: str) -> Sample:
    if not isinstance(answer, dict) or key not in answer:
        return sample
    return Sample(sample.route, sample.status, sample.seconds, str(answer[key]))


def _client_rounds(
    base: str, client: Client, seed: Seed, take: bytes, rounds: int, index: int, think_s: float
) -> list[Sample]:
    """One client's requests: ``rounds`` rounds of reads, and writes for a reviewer, with a
    pause of 0 to ``2 * think_s`` seconds (seeded by the client's index) before each."""
    samples: list[Sample] = []
    http = Connection(base, client.token)
    pauses = np.random.default_rng(index).uniform(0.0, 2.0 * think_s, size=10 * rounds)

    def pause() -> None:
        if think_s > 0:
            time.sleep(float(pauses[len(samples) % len(pauses)]))

    try:
        for turn in range(rounds):
            for route, url in (
                ("GET /me", "/me"),
                ("GET /takes", "/takes?limit=20"),
                ("GET /takes/{id}", f"/takes/{seed.take_id}"),
                ("GET /runs/{id}", f"/runs/{seed.run_id}"),
                ("GET /runs/{id}/decisions", f"/runs/{seed.run_id}/decisions"),
            ):
                pause()
                samples.append(http.request(route, "GET", url)[0])
            if not client.writes:
                continue
            name = f"load_{index:03d}_{turn:03d}.bvh"
            pause()
            sample, created = http.post_file("POST /takes", "/takes", name, take)
            samples.append(_created(sample, created, "id"))
            if created is not None:
                path = f"/takes/{created['id']}/runs"
                pause()
                samples.append(http.request("POST /takes/{id}/runs", "POST", path)[0])
            note = {"status": "needs_fix", "notes": f"client {index} round {turn}"}
            path = f"/takes/{seed.take_id}/reviews"
            pause()
            samples.append(http.post_json("POST /takes/{id}/reviews", path, note)[0])
            if seed.interval_ids:
                interval = seed.interval_ids[(index + turn) % len(seed.interval_ids)]
                decision = {"decision": "accept" if (index + turn) % 2 else "reject"}
                path = f"/runs/{seed.run_id}/intervals/{interval}/decisions"
                pause()
                sample, answer = http.post_json(
                    "POST /runs/{id}/intervals/{n}/decisions", path, decision
                )
                samples.append(_created(sample, answer, "id"))
    finally:
        http.close()
    return samples


@contextmanager
def _health_watch(base: str, result: LoadResult, every_s: float) -> Iterator[None]:
    """Ask ``/health`` every ``every_s`` seconds while the block runs."""
    stop = threading.Event()

    def watch() -> None:
        http = Connection(base, None)
        try:
            while not stop.is_set():
                result.health.append(http.request("GET /health", "GET", "/health")[0])
                stop.wait(every_s)
        finally:
            http.close()

    thread = threading.Thread(target=watch, name="health-watch", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join(timeout=REQUEST_TIMEOUT_S + 10)


def run_load(
    base: str,
    clients: Sequence[Client],
    seed: Seed,
    take: bytes,
    rounds: int,
    think_s: float = 0.0,
    health_every_s: float = 0.1,
) -> LoadResult:
    """Run every client at once for ``rounds`` rounds each, with ``/health`` watched.

    Parameters
    ----------
    base : str
        The server's URL (``http://127.0.0.1:PORT``).
    clients : sequence of Client
        One thread each, all started together.
    seed : Seed
        The take, run and intervals the clients read and decide on.
    take : bytes
        The BVH a writing client uploads each round.
    rounds : int
        Rounds per client (bounded: the run stops by itself).
    think_s : float
        Mean pause of a client before each request, seconds (0: back to back, the server's
        ceiling; a reviewer clicking through takes pauses a second or more).
    health_every_s : float
        Seconds between two health checks.
    """
    result = LoadResult(len(clients))
    gathered: list[list[Sample]] = [[] for _ in clients]
    start_line = threading.Barrier(len(clients))

    def work(index: int, client: Client) -> None:
        start_line.wait()
        gathered[index] = _client_rounds(base, client, seed, take, rounds, index, think_s)

    threads = [
        threading.Thread(target=work, args=(i, c), name=f"client-{i}", daemon=True)
        for i, c in enumerate(clients)
    ]
    return _run_together(base, result, threads, gathered, health_every_s)


def _run_together(
    base: str,
    result: LoadResult,
    threads: Sequence[threading.Thread],
    gathered: Sequence[Sequence[Sample]],
    health_every_s: float,
) -> LoadResult:
    """Start every thread, wait for all with ``/health`` watched, and put the samples they
    gathered and the wall-clock time into ``result``."""
    started = time.perf_counter()
    with _health_watch(base, result, health_every_s):
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    result.seconds = time.perf_counter() - started
    result.samples = [s for samples in gathered for s in samples]
    return result


def stream_frames(keypoints: int, frames: int) -> list[str]:
    """``frames`` frame messages of a live-filter stream of ``keypoints`` moving points (m)."""
    return [
        json.dumps({"positions": [[0.01 * f + 1e-3 * k, 1.0, 2.0] for k in range(keypoints)]})
        for f in range(frames)
    ]


def run_streams(
    base: str, token: str, streams: int, messages: Sequence[str], keypoints: int
) -> LoadResult:
    """``streams`` live-filter WebSocket streams at once, each sending ``messages`` one after
    the other (each waits for its answer), with ``/health`` watched; one sample per frame."""
    from websockets.sync.client import connect

    result = LoadResult(streams)
    gathered: list[list[Sample]] = [[] for _ in range(streams)]
    url = base.replace("http://", "ws://") + API + "/stream/filter"
    header = json.dumps({"fps": 30, "n_keypoints": keypoints, "length_unit": "m"})
    start_line = threading.Barrier(streams)

    def work(index: int) -> None:
        samples = gathered[index]
        headers = {"Authorization": f"Bearer {token}"}
        with connect(url, additional_headers=headers, max_size=None) as socket_:
            socket_.send(header)
            socket_.recv(timeout=REQUEST_TIMEOUT_S)
            start_line.wait()
            for message in messages:
                begin = time.perf_counter()
                socket_.send(message)
                answer = json.loads(socket_.recv(timeout=REQUEST_TIMEOUT_S))
                status = 500 if "error" in answer else 200
                samples.append(Sample("WS frame", status, time.perf_counter() - begin))

    threads = [threading.Thread(target=work, args=(i,), daemon=True) for i in range(streams)]
    return _run_together(base, result, threads, gathered, 0.1)


def route_figures(result: LoadResult) -> list[RouteFigures]:
    """Requests/s and p50/p95/p99/max latency per route (health last)."""
    by_route: dict[str, list[Sample]] = {}
    for sample in [*result.samples, *result.health]:
        by_route.setdefault(sample.route, []).append(sample)
    figures = []
    for route in sorted(by_route, key=lambda r: (r == "GET /health", r)):
        samples = by_route[route]
        ms = np.array([s.seconds for s in samples]) * 1000.0
        p50, p95, p99 = np.percentile(ms, [50, 95, 99])
        figures.append(
            RouteFigures(
                route=route,
                requests=len(samples),
                per_s=len(samples) / result.seconds if result.seconds > 0 else 0.0,
                p50_ms=float(p50),
                p95_ms=float(p95),
                p99_ms=float(p99),
                max_ms=float(ms.max()),
                errors_5xx=sum(1 for s in samples if s.status == 0 or s.status >= 500),
                refused_4xx=sum(1 for s in samples if 400 <= s.status < 500),
            )
        )
    return figures
