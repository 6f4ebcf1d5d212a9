"""Hostile inputs against a real server: each is refused with its 4xx before its cost is paid.

Every case is measured in this process (the server runs in a thread here): the time to the
answer, the peak of traced memory (``tracemalloc``, which NumPy reports to), the slowest
``/health`` answer while it ran (a poller thread), and that nothing was stored. The bounds are
generous (a loaded 2-core machine); the point is the orders of magnitude: the unguarded server
took 13–66 s and 3.3–3.8 GB for these. Sizes are smaller than the reports' (a 2 GB upload, a
104 MB BVH), with the limits lowered to match, so each case still crosses its limit by far.
The measured table is written to ``test-artifacts/hostile.md``.
"""

from __future__ import annotations

import io
import json
import socket
import threading
import time
import tracemalloc
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import httpx
import numpy as np
import pytest
from tests.api.conftest import make_settings
from tests.live_server import live_server, serve
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.store.roles import Role

ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts"
MAX_SECONDS = 20.0
"""Generous bound on a refusal (each takes well under a second on an idle machine)."""
MAX_PEAK_MB = 150.0
"""Generous bound on the traced memory of a refusal (inputs unpack to 80 MB to 3 GB)."""
MAX_HEALTH_S = 5.0
"""Slowest acceptable /health answer while a hostile request is handled."""


@dataclass
class Case:
    """One measured refusal."""

    name: str
    status: int
    seconds: float
    peak_mb: float
    health_s: float


ROWS: list[Case] = []


@pytest.fixture(scope="module")
def data_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The server's data folder."""
    return tmp_path_factory.mktemp("hostile")


@pytest.fixture(scope="module")
def settings(data_dir: Path) -> Settings:
    """Lowered upload and unpacked limits, the other limits at their defaults."""
    return make_settings(
        "sqlite",
        data_dir,
        max_upload_mb=8.0,
        max_unpacked_mb=20.0,
        uploads_per_minute_per_user=1000,
        allowed_hosts=["127.0.0.1", "localhost", "::1"],
    )


@pytest.fixture(scope="module", autouse=True)
def traced() -> Iterator[None]:
    """``tracemalloc`` on for the whole module, started before any server and stopped after
    the last one: stopping it while a server thread frees arrays can crash CPython 3.11."""
    tracemalloc.start()
    yield
    tracemalloc.stop()


@pytest.fixture(scope="module")
def url(settings: Settings, traced: None) -> Iterator[str]:
    """The server."""
    with live_server(settings) as base:
        yield base
    ARTIFACTS.mkdir(exist_ok=True)
    lines = ["| input | status | time (s) | peak memory (MB) | slowest /health (s) |"]
    lines.append("|---|---|---|---|---|")
    lines += [
        f"| {r.name} | {r.status} | {r.seconds:.3f} | {r.peak_mb:.1f} | {r.health_s:.3f} |"
        for r in ROWS
    ]
    (ARTIFACTS / "hostile.md").write_text("\n".join(lines) + "\n")


def stored(settings: Settings, url: str) -> tuple[int, list[str]]:
    """Takes in the database and files under takes/, runs/ and incoming/."""
    total = int(httpx.get(f"{url}/api/v1/takes").json()["total"])
    files = [
        str(p.relative_to(settings.data_dir))
        for sub in ("takes", "runs", "incoming")
        for p in (settings.data_dir / sub).rglob("*")
    ]
    return total, files


def measure(name: str, url: str, request: Callable[[], Any]) -> tuple[Any, Case]:
    """Run ``request`` while polling ``/health``; time, traced peak and slowest health."""
    latencies: list[float] = []
    stop = threading.Event()

    def poll() -> None:
        with httpx.Client(timeout=60) as client:
            while True:
                clock = time.perf_counter()
                assert client.get(f"{url}/api/v1/health").status_code == 200
                latencies.append(time.perf_counter() - clock)
                if stop.wait(0.02):
                    return

    poller = threading.Thread(target=poll, daemon=True)
    poller.start()
    assert tracemalloc.is_tracing(), "measure() needs the module's `traced` fixture"
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    clock = time.perf_counter()
    try:
        answer = request()
    finally:
        seconds = time.perf_counter() - clock
        peak = (tracemalloc.get_traced_memory()[1] - base) / 1e6
        stop.set()
        poller.join(timeout=120)
    status = getattr(answer, "status_code", 0)
    case = Case(name, status, seconds, peak, max(latencies, default=float("nan")))
    ROWS.append(case)
    assert latencies, "the server never answered /health"
    assert case.health_s < MAX_HEALTH_S, case
    assert case.seconds < MAX_SECONDS, case
    assert case.peak_mb < MAX_PEAK_MB, case
    return answer, case


def upload(url: str, name: str, data: bytes, **headers: str) -> httpx.Response:
    """POST a take."""
    return httpx.post(
        f"{url}/api/v1/takes", files={"file": (name, data)}, headers=headers, timeout=120
    )


def bvh_text(n_joints: int, chain: bool) -> str:
    """A BVH of one root and ``n_joints - 1`` joints, all under the root or in one chain."""
    parts = ["HIERARCHY", "ROOT Hips", "{", "OFFSET 0 0 0"]
    parts.append("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation")
    for i in range(1, n_joints):
        parts += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
        if not chain:
            parts.append("}")
    parts += ["End Site", "{", "OFFSET 0 1 0", "}"]
    parts += ["}"] * ((n_joints - 1 if chain else 0) + 1)
    values = " ".join(["0"] * (6 + 3 * (n_joints - 1)))
    parts += ["MOTION", "Frames: 2", "Frame Time: 0.0333333", values, values]
    return "\n".join(parts) + "\n"


def npz_bytes(n_frames: int, n_points: int) -> bytes:
    """A small compressed ``.npz`` claiming ``(n_frames, n_points, 3)`` float32 zeros."""
    buffer = io.BytesIO()
    np.savez_compressed(
        buffer, positions=np.zeros((n_frames, n_points, 3), np.float32), fps=np.float64(30)
    )
    return buffer.getvalue()


HOSTILE_UPLOADS: dict[str, tuple[str, Callable[[], bytes], int, str]] = {
    "400k-frame .npz (81 MB unpacked, 1.9 MB sent)": (
        "bomb.npz",
        lambda: npz_bytes(400_000, 17),
        413,
        "max_unpacked_bytes",
    ),
    "BVH with 20,000 joints": (
        "wide.bvh",
        lambda: bvh_text(20_000, chain=False).encode(),
        413,
        "max_joints",
    ),
    "999-joint BVH chain": (
        "chain.bvh",
        lambda: bvh_text(999, chain=True).encode(),
        413,
        "max_joints",
    ),
    "BVH claiming 10^7 frames": (
        "frames.bvh",
        lambda: bvh_text(2, chain=True).replace("Frames: 2", "Frames: 10000000").encode(),
        413,
        "max_frame_points",
    ),
    "CSV with one 5 MB line": (
        "line.csv",
        lambda: b"frame,time,a_x,a_y,a_z\n0,0," + b"1," * 2_500_000 + b"1\n",
        413,
        "max_line_bytes",
    ),
    "OpenPose JSON nested 100,000 deep": (
        "deep_000000000000_keypoints.json",
        lambda: b'{"people": ' + b"[" * 100_000 + b"]" * 100_000 + b"}",
        413,
        "max_json_depth",
    ),
    "MediaPipe JSON nested 100,000 deep": (
        "deep_landmarks.json",
        lambda: b'{"landmarks": ' + b"[" * 100_000 + b"]" * 100_000 + b"}",
        413,
        "max_json_depth",
    ),
}


@pytest.mark.parametrize("case", sorted(HOSTILE_UPLOADS))
def test_hostile_upload_is_refused_before_parsing(case: str, url: str, settings: Settings) -> None:
    name, make, status, setting = HOSTILE_UPLOADS[case]
    data = make()
    response, _ = measure(case, url, lambda: upload(url, name, data))
    assert response.status_code == status, response.text
    body = response.json()
    assert setting in body["detail"]
    assert body["error"] == "TooLargeError"
    assert stored(settings, url) == (0, [])


def test_upload_over_the_limit_is_refused_by_its_length(url: str, settings: Settings) -> None:
    data = b"0" * 40_000_000
    response, _ = measure("40 MB upload, Content-Length", url, lambda: upload(url, "a.bvh", data))
    assert response.status_code == 413
    assert "max_upload_mb" in response.json()["detail"]
    assert stored(settings, url) == (0, [])


def test_chunked_upload_over_the_limit_stops_at_the_limit(url: str, settings: Settings) -> None:
    """No Content-Length: the body is counted as it arrives; past the limit the app stops
    storing it and answers 413 (the server drains what the client still sends, unstored)."""
    boundary = "hostileboundary"
    sent = [0]

    def body() -> Iterator[bytes]:
        yield (
            f'--{boundary}\r\nContent-Disposition: form-data; name="file"; '
            'filename="big.bvh"\r\nContent-Type: application/octet-stream\r\n\r\n'
        ).encode()
        for _ in range(400):  # 400 MB if it were all read
            sent[0] += 1 << 20
            yield b"0" * (1 << 20)
        yield f"\r\n--{boundary}--\r\n".encode()

    def request() -> httpx.Response:
        try:
            return httpx.post(
                f"{url}/api/v1/takes",
                content=body(),
                headers={"Content-Type": f"multipart/form-data; boundary={boundary}"},
                timeout=120,
            )
        except httpx.HTTPError as e:  # the server may close while the client still sends
            return httpx.Response(599, text=str(e))

    response, _ = measure("chunked upload of 400 MB", url, request)
    assert response.status_code in (413, 599), response.text
    assert sent[0] > 8 << 20
    assert stored(settings, url) == (0, [])


def test_a_chunked_json_body_over_the_limit_names_the_limit(url: str) -> None:
    """A body sent without Content-Length is counted as it arrives; the 413 names the limit
    as it does for a Content-Length over it (it said only "Content Too Large")."""

    def body() -> Iterator[bytes]:
        yield b'{"name": "'
        for _ in range(3):
            yield b"x" * (1 << 20)
        yield b'"}'

    response = httpx.post(
        f"{url}/api/v1/shoots",
        content=body(),
        headers={"Content-Type": "application/json"},
        timeout=120,
    )
    assert response.status_code == 413, response.text
    assert response.json()["error"] == "TooLargeError"
    assert "max_request_kb" in response.json()["detail"]


@pytest.mark.parametrize(
    "path",
    [
        "/api/v1/takes?offset=9223372036854775808",
        "/api/v1/takes?limit=100000000000000000000000",
        "/api/v1/runs/0123456789abcdef0123456789abcdef/frames?step=100000000000000000000000",
        "/api/v1/runs/0123456789abcdef0123456789abcdef/frames?start=-1",
        "/api/v1/takes?status=bogus",
    ],
)
def test_query_integers_out_of_range_are_422(path: str, url: str) -> None:
    response, _ = measure(f"GET {path.split('/api/v1')[1]}", url, lambda: httpx.get(url + path))
    assert response.status_code == 422
    body = response.json()
    assert body["error"] == "ValidationError"
    assert body["field"].startswith("query.")


def test_cross_site_upload_is_403(url: str, settings: Settings, cmu_walk: Path) -> None:
    data = cmu_walk.read_bytes()
    headers = {"Origin": "https://elsewhere.example", "Sec-Fetch-Site": "cross-site"}
    response, _ = measure(
        "cross-site multipart upload", url, lambda: upload(url, "walk.bvh", data, **headers)
    )
    assert response.status_code == 403
    assert response.json()["error"] == "ForbiddenError"
    assert stored(settings, url) == (0, [])


def test_unknown_host_is_400(url: str) -> None:
    response, _ = measure(
        "Host: evil.example",
        url,
        lambda: httpx.get(f"{url}/api/v1/health", headers={"Host": "evil.example"}),
    )
    assert response.status_code == 400


def test_security_headers(url: str) -> None:
    page = httpx.get(f"{url}/")
    policy = page.headers["content-security-policy"]
    assert "script-src 'self'" in policy
    assert "frame-ancestors 'none'" in policy
    assert page.headers["x-content-type-options"] == "nosniff"
    assert page.headers["referrer-policy"] == "same-origin"
    assert "<script>" not in page.text  # the policy allows no inline script
    assert (
        "access-control-allow-origin"
        not in httpx.get(
            f"{url}/api/v1/health", headers={"Origin": "https://elsewhere.example"}
        ).headers
    )


def test_stream_refuses_huge_keypoint_count(url: str) -> None:
    ws_url = url.replace("http", "ws") + "/api/v1/stream/filter"

    def request() -> httpx.Response:
        with connect(ws_url) as socket:
            socket.send(json.dumps({"fps": 30, "n_keypoints": 10_000_000}))
            answer = json.loads(socket.recv(timeout=60))
        return httpx.Response(413 if "stream_max_keypoints" in answer.get("error", "") else 500)

    response, _ = measure("WebSocket n_keypoints=10^7", url, request)
    assert response.status_code == 413


@pytest.mark.parametrize(
    ("header", "words"),
    [
        ({"fps": 1e308, "n_keypoints": 17}, "at most 100000"),
        # Was accepted ("any rate above 0 is a rate"), and its first frame overflowed the
        # Kalman filter's dt⁴: the rate is bounded as every take's is (core/bounds.py).
        ({"fps": 1e-300, "n_keypoints": 17}, "at least 0.1"),
        ({"fps": 0.1, "n_keypoints": 17}, None),
        ({"fps": 30, "n_keypoints": 1.5}, "whole number"),
        ({"fps": 30, "n_keypoints": 17, "rate": 30}, "only the keys"),
    ],
)
def test_stream_header_is_checked_before_any_frame(
    url: str, header: dict[str, float], words: str | None
) -> None:
    ws_url = url.replace("http", "ws") + "/api/v1/stream/filter"
    with connect(ws_url) as socket:
        socket.send(json.dumps(header))
        answer = json.loads(socket.recv(timeout=60))
    if words is None:
        assert "error" not in answer, answer
    else:
        assert words in answer["error"], answer


def test_stream_refuses_huge_frame(url: str) -> None:
    ws_url = url.replace("http", "ws") + "/api/v1/stream/filter"
    frame = json.dumps({"positions": [[0.0, 0.0, 0.0]] * 200_000})

    def request() -> httpx.Response:
        with connect(ws_url, max_size=None, compression=None) as socket:
            socket.send(json.dumps({"fps": 30, "n_keypoints": 17}))
            json.loads(socket.recv(timeout=60))
            socket.send(frame)
            answer = json.loads(socket.recv(timeout=60))
        return httpx.Response(413 if "stream_max_frame_bytes" in answer.get("error", "") else 500)

    response, _ = measure("WebSocket 4 MB frame", url, request)
    assert response.status_code == 413


def test_stream_refuses_other_origins(url: str) -> None:
    ws_url = url.replace("http", "ws") + "/api/v1/stream/filter"

    def request() -> httpx.Response:
        try:
            with connect(ws_url, origin="https://elsewhere.example"):  # type: ignore[arg-type]
                return httpx.Response(101)
        except InvalidStatus as e:
            return httpx.Response(e.response.status_code)

    response, _ = measure("WebSocket from another Origin", url, request)
    assert response.status_code == 403


SMALL_TAKE = bvh_text(3, chain=True).encode()
"""An accepted take whose analysis takes moments (the quota tests wait for their runs)."""
RUN_BOUND_S = 600.0
"""Generous bound on the runs of :data:`SMALL_TAKE` (seconds)."""


def upload_and_finish(url: str, count: int, **headers: str) -> list[int]:
    """Upload :data:`SMALL_TAKE` ``count`` times and wait for the runs to end, so that the
    measured refusal that follows is not sharing the process with analyses."""
    answers = [upload(url, "small.bvh", SMALL_TAKE, **headers) for _ in range(count)]
    deadline = time.monotonic() + RUN_BOUND_S
    for answer in answers:
        if answer.status_code != 201:
            continue
        run = f"{url}/api/v1/runs/{answer.json()['run_id']}"
        while httpx.get(run, headers=headers, timeout=60).json()["status"] in ("queued", "running"):
            assert time.monotonic() < deadline, "the upload's run did not end"
            time.sleep(0.1)
    return [a.status_code for a in answers]


def test_anonymous_upload_rate_is_limited_per_address(tmp_path: Path) -> None:
    """A server without users: the budget is the client address's."""
    settings = make_settings(
        "sqlite", tmp_path, uploads_per_minute_per_user=2, allowed_hosts=["127.0.0.1"]
    )
    data = SMALL_TAKE
    with live_server(settings) as base:
        statuses = upload_and_finish(base, 2)
        response, _ = measure(
            "3rd anonymous upload in a minute from one address (limit 2)",
            base,
            lambda: upload(base, "w.bvh", data),
        )
    assert statuses == [201, 201]
    assert response.status_code == 429
    assert 1 <= int(response.headers["retry-after"]) <= 61


def raw_request(url: str, head: str, body: bytes = b"", wait_s: float = 120.0) -> httpx.Response:
    """Send a request's head (and the start of its body) on a socket, then read the answer
    without sending the rest: a server waiting for the body would never answer (the read
    then times out after ``wait_s`` and the test fails)."""
    address = urlsplit(url)
    with socket.create_connection((address.hostname, address.port), timeout=wait_s) as sock:
        sock.sendall(head.encode() + body)
        data = b""
        while b"\r\n\r\n" not in data:
            chunk = sock.recv(65536)
            if not chunk:
                return httpx.Response(599, text="closed before answering")
            data += chunk
        start, _, rest = data.partition(b"\r\n\r\n")
        lines = start.decode("latin-1").split("\r\n")
        headers = dict(line.split(": ", 1) for line in lines[1:])
        length = int({k.lower(): v for k, v in headers.items()}.get("content-length", "0"))
        while len(rest) < length and (chunk := sock.recv(65536)):
            rest += chunk
    return httpx.Response(int(lines[0].split()[1]), headers=headers, content=rest[:length])


@pytest.fixture
def team(tmp_path: Path) -> Iterator[tuple[str, Settings, dict[str, dict[str, str]]]]:
    """A server with two reviewers, ``alice`` and ``bob`` (both on 127.0.0.1), two uploads a
    minute each; yields the URL, the settings and each one's Bearer header."""
    settings = make_settings(
        "sqlite", tmp_path, uploads_per_minute_per_user=2, allowed_hosts=["127.0.0.1"]
    )
    app = create_app(settings)
    accounts = app.state.accounts
    bearers = {
        name: {
            "Authorization": "Bearer "
            + accounts.issue(
                accounts.add_user(name, Role.REVIEWER).id, "api", timedelta(days=1)
            ).token
        }
        for name in ("alice", "bob")
    }
    with serve(app) as url:
        yield url, settings, bearers


def test_upload_rate_is_per_user_and_checked_before_the_body(
    team: tuple[str, Settings, dict[str, dict[str, str]]],
) -> None:
    """Two users behind one address each have their own budget; the one over it gets 429 with
    ``Retry-After`` before a byte of the body is read (an endless chunked body, a 2 GB
    Content-Length), while the other one's uploads still succeed; an anonymous upload to this
    server gets its 401 before its body too."""
    url, settings, bearers = team
    alice, bob = bearers["alice"], bearers["bob"]
    data = SMALL_TAKE
    assert upload_and_finish(url, 2, **alice) == [201, 201]

    refused, _ = measure(
        "3rd upload of a user in a minute (limit 2)",
        url,
        lambda: upload(url, "small.bvh", data, **alice),
    )
    assert refused.status_code == 429, refused.text
    assert 1 <= int(refused.headers["retry-after"]) <= 61
    assert refused.json()["error"] == "RateLimitError"
    assert "uploads_per_minute_per_user" in refused.json()["detail"]

    host = urlsplit(url).netloc
    head = f"POST /api/v1/takes HTTP/1.1\r\nHost: {host}\r\n"
    head += f"Authorization: {alice['Authorization']}\r\n"
    head += "Content-Type: multipart/form-data; boundary=b\r\n"
    chunked, _ = measure(
        "user over the upload rate: chunked body, 1 MB of an endless one sent",
        url,
        lambda: raw_request(
            url, head + "Transfer-Encoding: chunked\r\n\r\n", b"100000\r\n" + b"0" * (1 << 20)
        ),
    )
    assert chunked.status_code == 429, chunked.text
    assert int(chunked.headers["retry-after"]) >= 1
    assert "uploads_per_minute_per_user" in chunked.json()["detail"]
    declared, _ = measure(
        "user over the upload rate: Content-Length 2 GB, no body sent",
        url,
        lambda: raw_request(url, head + "Content-Length: 2000000000\r\n\r\n"),
    )
    assert declared.status_code == 429, declared.text
    anonymous, _ = measure(
        "anonymous upload to a server with users: Content-Length 2 GB, no body sent",
        url,
        lambda: raw_request(
            url,
            f"POST /api/v1/takes HTTP/1.1\r\nHost: {host}\r\n"
            "Content-Type: multipart/form-data; boundary=b\r\nContent-Length: 2000000000\r\n\r\n",
        ),
    )
    assert anonymous.status_code == 401, anonymous.text
    assert anonymous.json()["error"] == "AuthenticationError"

    # Meanwhile (alice still over her budget) bob, behind the same address, uploads; his own
    # budget is 2 too. Not measured: his runs start at once (see upload_and_finish).
    assert upload_and_finish(url, 3, **bob) == [201, 201, 429]
    assert upload(url, "small.bvh", data, **alice).status_code == 429

    takes = httpx.get(f"{url}/api/v1/takes", headers=alice, timeout=60).json()
    assert takes["total"] == 4  # two of alice's, two of bob's; nothing of the refused ones
    assert sorted(p.name for p in (settings.data_dir / "takes").iterdir()) == sorted(
        t["id"] for t in takes["items"]
    )
    assert list((settings.data_dir / "incoming").iterdir()) == []


FRAME_POINTS_PEAK_MB = 30.0
"""Bound on the traced memory of these refusals: parsed, they take 59–335 MB (measured with
``tracemalloc``: 76 MB the TRC, 170 and 335 MB the long CSVs, 59 and 169 MB the sparse ones)."""
FRAME_POINT_UPLOADS: dict[str, tuple[str, Callable[[], bytes]]] = {
    "keypoint CSV of 500,000 lines (limit 200,000 frames × points)": (
        "long.csv",
        lambda: (
            b"frame,keypoint,x,y,z\n"
            + b"".join(b"%d,k%d,0,0,0\n" % (i // 17, i % 17) for i in range(500_000))
        ),
    ),
    "MediaPipe CSV of 400,000 lines (limit 200,000 frames × points)": (
        "landmarks.csv",
        lambda: (
            b"frame_number,landmark,x,y,z,visibility\n"
            + b"".join(b"%d,%d,0,0,0,1\n" % (i // 33, i % 33) for i in range(400_000))
        ),
    ),
    "TRC of 5,000 frames × 100 markers (limit 200,000)": (
        "markers.trc",
        lambda: trc_bytes(5000, 100),
    ),
    # Few lines, but frame numbers and names that span far more (refused before the arrays).
    "keypoint CSV of 1,000 lines spanning 4,000 frames × 1,000 keypoints": (
        "sparse.csv",
        lambda: (
            b"frame,keypoint,x,y\n" + b"".join(b"%d,k%d,0,0\n" % (4 * i, i) for i in range(1000))
        ),
    ),
    "MediaPipe CSV of 10,000 lines spanning 40,000 frames × 33": (
        "sparse_landmarks.csv",
        lambda: (
            b"frame_number,landmark,x,y,z\n"
            + b"".join(b"%d,0,0,0,0\n" % (4 * i) for i in range(10_000))
        ),
    ),
}


def trc_bytes(n_frames: int, n_markers: int) -> bytes:
    """A TRC of ``n_frames`` rows of ``n_markers`` markers at the origin."""
    names = "\t\t\t".join(f"M{i}" for i in range(n_markers))
    labels = "\t".join(f"X{i}\tY{i}\tZ{i}" for i in range(1, n_markers + 1))
    head = [
        "PathFileType\t4\t(X/Y/Z)\tmarkers.trc",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
        "\tOrigNumFrames",
        f"60\t60\t{n_frames}\t{n_markers}\tm\t60\t1\t{n_frames}",
        f"Frame#\tTime\t{names}",
        f"\t\t{labels}",
        "",
    ]
    row = "\t".join(["0"] * (3 * n_markers))
    rows = [f"{i + 1}\t{i / 60:.5f}\t{row}" for i in range(n_frames)]
    return ("\n".join(head + rows) + "\n").encode()


@pytest.fixture(scope="module")
def small_frames_url(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[str, Settings]]:
    """A server allowing 200,000 frames × points (so an 8 MB upload can cross it by far)."""
    settings = make_settings(
        "sqlite",
        tmp_path_factory.mktemp("frames"),
        max_upload_mb=8.0,
        max_frame_points=200_000,
        uploads_per_minute_per_user=1000,
        allowed_hosts=["127.0.0.1"],
    )
    with live_server(settings) as base:
        yield base, settings


@pytest.mark.parametrize("case", sorted(FRAME_POINT_UPLOADS))
def test_frames_times_points_are_counted_before_parsing(
    case: str, small_frames_url: tuple[str, Settings]
) -> None:
    url, settings = small_frames_url
    name, make = FRAME_POINT_UPLOADS[case]
    data = make()
    assert len(data) < 8_000_000
    response, measured = measure(case, url, lambda: upload(url, name, data))
    assert response.status_code == 413, response.text
    assert measured.peak_mb < FRAME_POINTS_PEAK_MB, measured
    body = response.json()
    assert body["error"] == "TooLargeError"
    assert "max_frame_points" in body["detail"]
    assert body["detail"].startswith(f"{name}:")
    assert stored(settings, url) == (0, [])


@pytest.mark.parametrize(
    ("host", "status"),
    [
        ("[::1]:8000", 200),
        ("[::1]", 200),
        ("[0:0:0:0:0:0:0:1]:80", 200),
        ("[::2]:8000", 400),
        ("[evil.example]:8000", 400),
        ("[::1", 400),
        ("::1", 400),
    ],
)
def test_ipv6_host_header(host: str, status: int, url: str) -> None:
    """The module's server allows ``::1`` (written without brackets in the setting)."""
    response, _ = measure(
        f"Host: {host}",
        url,
        lambda: httpx.get(f"{url}/api/v1/health", headers={"Host": host}),
    )
    assert response.status_code == status, response.text
    if status == 400:
        assert response.json()["error"] == "HostError"


def test_stream_work_stays_off_the_event_loop(url: str) -> None:
    """An allowed but heavy stream (1000 keypoints a frame) leaves /health answering."""
    ws_url = url.replace("http", "ws") + "/api/v1/stream/filter"
    rng = np.random.default_rng(15)
    frames = [
        json.dumps({"positions": rng.normal(size=(1000, 3)).round(4).tolist()}) for _ in range(30)
    ]

    def request() -> httpx.Response:
        with connect(ws_url, max_size=None, compression=None) as socket:
            socket.send(json.dumps({"fps": 30, "n_keypoints": 1000, "length_unit": "m"}))
            assert json.loads(socket.recv(timeout=300))["ready"]
            for frame in frames:
                socket.send(frame)
                answer = json.loads(socket.recv(timeout=300))
                assert len(answer["positions"]) == 1000, answer
        return httpx.Response(200)

    response, _ = measure("WebSocket 30 frames × 1000 keypoints (allowed)", url, request)
    assert response.status_code == 200


def test_large_unmarked_json_is_not_parsed_to_detect_it(url: str, settings: Settings) -> None:
    """A 6 MB JSON with no format marker up front is told apart without parsing it (parsed,
    its 1.8 million values would take about 70 MB of traced memory before any limit; it is
    refused by its line length instead)."""
    data = b"[" + b",".join([b"[0.5,0.5,0.5]"] * 450_000) + b"]"
    response, case = measure(
        "6 MB unmarked JSON array (450,000 numbers × 3)", url, lambda: upload(url, "a.json", data)
    )
    assert response.status_code == 413, response.text
    assert case.peak_mb < 30
    assert stored(settings, url) == (0, [])
