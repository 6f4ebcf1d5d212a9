"""Import limits paid before their cost (issue 32): an archive member over the upload limit is
cut while it is written (listed as failed, the other members imported), and each user may
have at most ``max_concurrent_imports_per_user`` imports at once and
``max_incoming_mb_per_user`` staged in ``incoming/`` — past either, a request gets 429 with
``Retry-After`` before its body is read (or its archive unpacked), and 413 when it could never
fit alone."""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import timedelta
from pathlib import Path
from typing import Any, BinaryIO
from urllib.parse import urlsplit

import httpx
import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import make_settings
from tests.api.test_hostile_pass import SMALL_BVH, deflated_zip
from tests.live_server import read_answer, serve

import mocapqa.jobs.shoot_import as shoot_import
from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.jobs.archive import unpack
from mocapqa.jobs.intake import ingest_take
from mocapqa.store.roles import Role

WAIT_S = 120.0
"""Generous bound on one answer of the live server (a loaded 2-core machine)."""


def new_shoot(client: TestClient | httpx.Client) -> str:
    response = client.post("/api/v1/shoots", json={"name": "day one"})
    assert response.status_code == 201, response.text
    return str(response.json()["id"])


def largest_file(folder: Path) -> int:
    return max((p.stat().st_size for p in folder.rglob("*") if p.is_file()), default=0)


def test_an_archive_member_over_the_upload_limit_fails_alone_and_is_never_written_whole(
    settings: Settings, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 1.8 MB zip holding a 1.9 GB member of zeros wrote it whole to ``incoming/`` before
    refusing it. With ``max_upload_mb`` at 0.01 (10,000 bytes), a 1 MB member of zeros is cut
    at the limit while it is unpacked: no file in ``incoming/`` is ever larger than the limit
    (looked at whenever a member is stored), the member is failed naming the setting, and the
    members beside it are imported."""
    limit = 10_000
    tiny = settings.model_copy(update={"max_upload_mb": limit / 1_000_000})
    largest: list[int] = []

    def watched(*args: Any, **kwargs: Any) -> tuple[str, str]:
        largest.append(largest_file(tiny.data_dir / "incoming"))
        return ingest_take(*args, **kwargs)

    monkeypatch.setattr(shoot_import, "ingest_take", watched)
    archive = deflated_zip({"a.bvh": SMALL_BVH, "zeros.bvh": bytes(1_000_000), "b.bvh": SMALL_BVH})
    assert len(archive) < limit
    with TestClient(create_app(tiny)) as client:
        response = client.post(
            f"/api/v1/shoots/{new_shoot(client)}/takes", files=[("files", ("day.zip", archive))]
        )
    assert response.status_code == 201, response.text
    assert len(largest) == 2
    assert max(largest) <= limit
    body = response.json()
    assert sorted(c["name"] for c in body["created"]) == ["a.bvh", "b.bvh"]
    assert body["failed"] == [
        {
            "name": "day.zip:zeros.bvh",
            "error": f"Expected a member of at most {limit} bytes (the upload limit, setting "
            "max_upload_mb), got more",
        }
    ]
    assert list((tiny.data_dir / "incoming").iterdir()) == []


def test_an_archive_unpacking_past_the_staging_allowance_is_refused_before_unpacking(
    settings: Settings, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An archive whose declared unpacked size, with the request's own bytes, passes
    ``max_incoming_mb_per_user`` could never fit: 413 naming the setting, before any member
    is written, and nothing imported."""
    small = settings.model_copy(update={"max_incoming_mb_per_user": 0.05})
    written: list[str] = []

    def watched(*args: Any, **kwargs: Any) -> Any:
        members = unpack(*args, **kwargs)
        written.extend(m.name for m in members)
        return members

    monkeypatch.setattr(shoot_import, "unpack", watched)
    archive = deflated_zip({f"t{i}.bvh": bytes(20_000) for i in range(4)})
    with TestClient(create_app(small)) as client:
        shoot_id = new_shoot(client)
        response = client.post(
            f"/api/v1/shoots/{shoot_id}/takes", files=[("files", ("day.zip", archive))]
        )
        assert response.status_code == 413, response.text
        detail = response.json()["detail"]
        assert "(setting max_incoming_mb_per_user)" in detail
        assert "80000 unpacked" in detail
        assert client.get(f"/api/v1/shoots/{shoot_id}").json()["n_takes"] == 0
        # A small archive fits: the allowance held for the refused one was given back.
        fits = deflated_zip({"a.bvh": SMALL_BVH})
        response = client.post(
            f"/api/v1/shoots/{shoot_id}/takes", files=[("files", ("ok.zip", fits))]
        )
        assert response.status_code == 201, response.text
    assert written == ["a.bvh"]
    assert list((small.data_dir / "incoming").iterdir()) == []


def head(url: str, path: str, token: str, length: int, expect: bool = False) -> bytes:
    """A multipart POST's head announcing ``length`` bytes of body (never sent)."""
    text = f"POST {path} HTTP/1.1\r\nHost: {urlsplit(url).netloc}\r\n"
    text += f"Authorization: Bearer {token}\r\n"
    text += "Content-Type: multipart/form-data; boundary=b\r\n"
    if expect:
        text += "Expect: 100-continue\r\n"
    return f"{text}Content-Length: {length}\r\n\r\n".encode()


def connect(url: str) -> socket.socket:
    address = urlsplit(url)
    return socket.create_connection((address.hostname, address.port), timeout=WAIT_S)


@contextmanager
def held(url: str, path: str, token: str, length: int = 100_000_000) -> Iterator[None]:
    """A request past the guard, holding its place: its head asks ``Expect: 100-continue``
    and the server's ``100 Continue`` (sent when the route first reads the body, after the
    guard admitted it) is awaited; the body is never sent, the socket closed on leaving."""
    with connect(url) as sock:
        sock.sendall(head(url, path, token, length, expect=True))
        data = b""
        while b"\r\n\r\n" not in data and (chunk := sock.recv(65536)):
            data += chunk
        assert data.startswith(b"HTTP/1.1 100"), data
        yield


def answer(url: str, request: bytes) -> tuple[int, dict[str, str], dict[str, Any]]:
    """Send a request's head only and read the answer (given before the body, or never)."""
    with connect(url) as sock:
        sock.sendall(request)
        return read_answer(sock)


def import_until_admitted(http: httpx.Client, shoot_id: str, files: BinaryIO | bytes) -> int:
    """Post a small import until it is not 429: the places held by closed requests are given
    back when the server notices the disconnection (bounded by :data:`WAIT_S`)."""
    deadline = time.monotonic() + WAIT_S
    while True:
        response = http.post(
            f"/api/v1/shoots/{shoot_id}/takes", files=[("files", ("t.bvh", files))]
        )
        if response.status_code != 429 or time.monotonic() > deadline:
            return response.status_code
        time.sleep(0.05)


@contextmanager
def live(tmp_path: Path, **changes: Any) -> Iterator[tuple[str, str, str, httpx.Client]]:
    """A live server with a reviewer: its URL, token, a shoot's id and a signed-in client."""
    settings = make_settings("sqlite", tmp_path, allowed_hosts=["127.0.0.1"], **changes)
    app = create_app(settings)
    accounts = app.state.accounts
    reviewer = accounts.add_user("rita", Role.REVIEWER)
    token = accounts.issue(reviewer.id, "api", timedelta(days=1)).token
    with serve(app) as url:
        auth = {"Authorization": f"Bearer {token}"}
        with httpx.Client(base_url=url, headers=auth, timeout=WAIT_S) as http:
            yield url, token, new_shoot(http), http
    assert list((settings.data_dir / "incoming").iterdir()) == []


def test_imports_past_the_per_user_limit_at_once_are_429_before_their_body(
    tmp_path: Path,
) -> None:
    """Two imports of a user in progress (their bodies not yet sent): a third is refused from
    its head alone with 429 and ``Retry-After``, naming the setting; another user's import is
    not. Once the two end, the user's imports are admitted again."""
    with live(tmp_path, max_concurrent_imports_per_user=2) as (url, token, shoot_id, http):
        path = f"/api/v1/shoots/{shoot_id}/takes"
        with held(url, path, token), held(url, path, token):
            status, headers, body = answer(url, head(url, path, token, 100_000_000))
            assert status == 429, body
            assert int(headers["retry-after"]) >= 1
            assert body["error"] == "RateLimitError"
            assert "at most 2 imports at once per user (setting " in body["detail"]
            assert "max_concurrent_imports_per_user" in body["detail"]
        assert import_until_admitted(http, shoot_id, SMALL_BVH) == 201


def test_uploads_past_the_per_user_staging_allowance_are_refused_before_their_body(
    tmp_path: Path,
) -> None:
    """With 150 MB allowed per user in ``incoming/`` and an import of 100 MB in progress, an
    import or an upload announcing 100 MB more gets 429 with ``Retry-After`` from its head;
    a small upload fits beside it. A request announcing more than the allowance alone could
    never fit: 413, naming the setting."""
    with live(tmp_path, max_incoming_mb_per_user=150.0) as (url, token, shoot_id, http):
        path = f"/api/v1/shoots/{shoot_id}/takes"
        alone = answer(url, head(url, path, token, 160_000_000))
        assert alone[0] == 413, alone
        assert "(setting max_incoming_mb_per_user), got 160000000" in alone[2]["detail"]
        with held(url, path, token):
            for target in (path, "/api/v1/takes"):
                status, headers, body = answer(url, head(url, target, token, 100_000_000))
                assert status == 429, (target, body)
                assert int(headers["retry-after"]) >= 1
                assert "(setting max_incoming_mb_per_user)" in body["detail"]
                assert "100000000 held by requests in progress" in body["detail"]
            small = http.post("/api/v1/takes", files={"file": ("s.bvh", SMALL_BVH)})
            assert small.status_code == 201, small.text
        assert import_until_admitted(http, shoot_id, SMALL_BVH) == 201
