"""A hostile client's pass over the API, in process: text the database cannot store (NUL,
unpaired surrogates) in paths, queries and JSON bodies, and a shoot import cut short by a
limit. Each answer must be a 4xx naming the field, and nothing stored may become unreadable
or ownerless. Runs on SQLite and (``scripts/with-postgres.sh``) on PostgreSQL, which refuses
NUL in text."""

from __future__ import annotations

import io
import socket
import zipfile
from datetime import timedelta
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import make_settings
from tests.live_server import read_answer, serve

from mocapqa.api.app import create_app
from mocapqa.store.roles import Role

SMALL_BVH = b"""HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.033333
0 0 0 0 0 0 0 0 0
1 1 1 1 1 1 1 1 1
2 2 2 2 2 2 2 2 2
"""


def bearer(client: TestClient, name: str, role: Role) -> tuple[int, dict[str, str]]:
    """A new user of ``role`` and its Bearer header."""
    accounts = client.app.state.accounts  # type: ignore[attr-defined]
    user = accounts.add_user(name, role)
    token = accounts.issue(user.id, "api", timedelta(days=1)).token
    return user.id, {"Authorization": f"Bearer {token}"}


def upload(client: TestClient, headers: dict[str, str]) -> dict[str, Any]:
    response = client.post(
        "/api/v1/takes", files={"file": ("small.bvh", SMALL_BVH)}, headers=headers
    )
    assert response.status_code == 201, response.text
    body: dict[str, Any] = response.json()
    return body


@pytest.fixture
def alice(client: TestClient) -> tuple[int, dict[str, str]]:
    """A reviewer."""
    return bearer(client, "alice", Role.REVIEWER)


def assert_refused(response: Any, field: str) -> None:
    assert response.status_code == 422, response.text
    body = response.json()
    assert body["error"] == "ValidationError"
    assert body["field"] == field, body
    assert "NUL" in body["detail"] or "surrogate" in body["detail"], body


@pytest.mark.parametrize(
    "path",
    [
        "/api/v1/takes/%00",
        "/api/v1/runs/%00/result",
        "/api/v1/shoots/a%00b/takes",
        "/api/v1/takes/%00/reviews",
        "/api/v1/runs/%00/decisions",
    ],
)
def test_nul_in_the_path_is_422_before_the_database(
    path: str, client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """PostgreSQL refuses NUL in text: an id holding one used to be a 500 there."""
    assert_refused(client.get(path, headers=alice[1]), "path")


def test_nul_in_the_path_of_a_change_is_422(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    take = upload(client, alice[1])
    assert_refused(client.delete("/api/v1/takes/%00", headers=alice[1]), "path")
    assert_refused(client.post("/api/v1/takes/%00/runs", json={}, headers=alice[1]), "path")
    assert_refused(client.delete("/api/v1/tokens/%00", headers=alice[1]), "path")
    assert client.get(f"/api/v1/takes/{take['id']}", headers=alice[1]).status_code == 200


def test_nul_in_a_query_is_422_naming_it(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    shoot = client.post("/api/v1/shoots", json={"name": "day one"}, headers=alice[1]).json()
    for name in ("search", "rig"):
        response = client.get(f"/api/v1/shoots/{shoot['id']}/takes?{name}=a%00", headers=alice[1])
        assert_refused(response, f"query.{name}")
    response = client.delete(f"/api/v1/shoots/{shoot['id']}?confirm=%00", headers=alice[1])
    assert_refused(response, "query.confirm")
    assert client.get(f"/api/v1/shoots/{shoot['id']}", headers=alice[1]).status_code == 200


def test_a_json_key_sent_twice_is_422_naming_it(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """Python's JSON parser keeps the last of a repeated key: ``{"name": "x", "name": "y"}``
    made a shoot "y"; nested objects (run options' ``filter_params``) too."""
    headers = {**alice[1], "content-type": "application/json"}
    response = client.post("/api/v1/shoots", content=b'{"name": "x", "name": "y"}', headers=headers)
    assert response.status_code == 422, response.text
    assert response.json()["field"] == "body.name"
    assert "twice" in response.json()["detail"]
    assert client.get("/api/v1/shoots", headers=alice[1]).json() == []
    take = upload(client, alice[1])
    nested = (
        b'{"filter_method": "ema", "filter_params": {"time_constant_s": 1, "time_constant_s": 2}}'
    )
    response = client.post(f"/api/v1/takes/{take['id']}/runs", content=nested, headers=headers)
    assert response.status_code == 422, response.text
    assert response.json()["field"] == "body.time_constant_s"
    # The same key in two objects is two keys; invalid JSON is FastAPI's own 422.
    made = client.post("/api/v1/shoots", content=b'{"name": "z"}', headers=headers)
    assert made.status_code == 201, made.text
    assert client.post("/api/v1/shoots", content=b'{"name": ', headers=headers).status_code == 422


def test_a_query_parameter_read_once_and_sent_twice_is_422_naming_it(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """Starlette keeps the last value: ``?limit=5&limit=500`` would page by 500 while a log in
    front of the server read 5, and ``?confirm=`` twice would delete on the second name."""
    shoot = client.post("/api/v1/shoots", json={"name": "day two"}, headers=alice[1]).json()
    takes = f"/api/v1/shoots/{shoot['id']}/takes"
    response = client.get(f"{takes}?limit=5&limit=500", headers=alice[1])
    assert response.status_code == 422, response.text
    assert response.json()["field"] == "query.limit"
    assert "got 2" in response.json()["detail"]
    # In a dependency of the route (the table's filters) too.
    response = client.get(f"{takes}?rig=cmu&rig=bandai", headers=alice[1])
    assert response.json()["field"] == "query.rig"
    response = client.delete(
        f"/api/v1/shoots/{shoot['id']}?confirm=other&confirm=day%20two", headers=alice[1]
    )
    assert response.status_code == 422
    assert response.json()["field"] == "query.confirm"
    assert client.get(f"/api/v1/shoots/{shoot['id']}", headers=alice[1]).status_code == 200
    # Once each, and a parameter the route does not read, are as before.
    assert client.get(f"{takes}?limit=5&offset=0", headers=alice[1]).status_code == 200
    assert client.get(f"{takes}?unknown=1&unknown=2", headers=alice[1]).status_code == 200


@pytest.mark.parametrize(
    ("path", "body", "field"),
    [
        ("/api/v1/shoots", b'{"name": "day\\u0000one"}', "body.name"),
        ("/api/v1/tokens", b'{"name": "laptop\\u0000"}', "body.name"),
        ("/api/v1/auth/sign-in", b'{"name": "a\\u0000", "password": "x"}', "body.name"),
        ("/api/v1/shoots", b'{"name": "day \\udfff"}', "body.name"),
    ],
)
def test_nul_or_surrogate_in_a_body_is_422_naming_the_field(
    path: str, body: bytes, field: str, client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    headers = {**alice[1], "Content-Type": "application/json"}
    assert_refused(client.post(path, content=body, headers=headers), field)


@pytest.mark.parametrize(
    ("options", "field"),
    [
        (b'{"mapping": {"left_upper_arm": "Left\\udfffArm"}}', "body.mapping"),
        (b'{"mapping": {"left_upper_arm": "Left\\u0000Arm"}}', "body.mapping"),
        (b'{"filter_params": {"window_s": "\\ud800"}}', "body.filter_params"),
        (b'{"twist_apply": "0,\\udfff"}', "body.twist_apply"),
    ],
)
def test_unstorable_run_options_are_422_and_the_take_stays_readable(
    options: bytes, field: str, client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """An unpaired surrogate in a run option was stored with the run, then every answer that
    listed the take's runs failed to encode it: the take's page was a 500 for everyone."""
    take = upload(client, alice[1])
    response = client.post(
        f"/api/v1/takes/{take['id']}/runs",
        content=options,
        headers={**alice[1], "Content-Type": "application/json"},
    )
    assert_refused(response, field)
    detail = client.get(f"/api/v1/takes/{take['id']}", headers=alice[1])
    assert detail.status_code == 200, detail.text
    assert len(detail.json()["runs"]) == 1


def test_review_and_decision_text_with_nul_is_422(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    take = upload(client, alice[1])
    headers = {**alice[1], "Content-Type": "application/json"}
    response = client.post(
        f"/api/v1/takes/{take['id']}/reviews",
        content=b'{"status": "approved", "notes": "ok\\u0000"}',
        headers=headers,
    )
    assert_refused(response, "body.notes")
    assert client.get(f"/api/v1/takes/{take['id']}/reviews", headers=alice[1]).json() == []


def deflated_zip(members: dict[str, bytes]) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return buffer.getvalue()


@pytest.fixture
def small_archives(settings: Any) -> Any:
    """Settings whose imported archives may unpack to 1 MB."""
    return settings.model_copy(update={"archive_max_unpacked_mb": 1.0})


def test_import_cut_short_by_a_limit_keeps_its_takes_owned(
    small_archives: Any, tmp_path: Path
) -> None:
    """An import whose second file is an archive over the unpacked limit answers 413; the take
    made from its first file stays, owned by the importer (who may delete it), not ownerless
    (which only an admin could delete)."""
    with TestClient(create_app(small_archives)) as client:
        user_id, headers = bearer(client, "alice", Role.REVIEWER)
        shoot = client.post("/api/v1/shoots", json={"name": "day one"}, headers=headers).json()
        bomb = deflated_zip({"big.bvh": b"0" * 3_000_000})
        response = client.post(
            f"/api/v1/shoots/{shoot['id']}/takes",
            files=[("files", ("first.bvh", SMALL_BVH)), ("files", ("bomb.zip", bomb))],
            headers=headers,
        )
        assert response.status_code == 413, response.text
        assert "archive_max_unpacked_mb" in response.json()["detail"]
        takes = client.get("/api/v1/takes", headers=headers).json()["items"]
        assert [(t["name"], t["owner_id"]) for t in takes] == [("first.bvh", user_id)]
        deleted = client.delete(f"/api/v1/takes/{takes[0]['id']}", headers=headers)
        assert deleted.status_code == 204, deleted.text


def test_a_mapping_to_a_joint_the_take_lacks_is_422_before_queueing(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """Run options are checked when the run is asked for: a mapping naming a joint the BVH
    does not have used to queue a run that failed later ("Expected a joint of this
    skeleton")."""
    take = upload(client, alice[1])
    response = client.post(
        f"/api/v1/takes/{take['id']}/runs",
        json={"mapping": {"left_upper_arm": "NoSuchJoint"}},
        headers=alice[1],
    )
    assert response.status_code == 422, response.text
    body = response.json()
    assert body["error"] == "OptionError"
    assert body["field"] == "mapping.left_upper_arm"
    assert "NoSuchJoint" in body["detail"]
    detail = client.get(f"/api/v1/takes/{take['id']}", headers=alice[1]).json()
    assert len(detail["runs"]) == 1
    accepted = client.post(
        f"/api/v1/takes/{take['id']}/runs",
        json={"mapping": {"left_upper_arm": "Spine"}},
        headers=alice[1],
    )
    assert accepted.status_code == 201, accepted.text
    # A mapping against the hierarchy (the upper arm above its clavicle) is refused here too,
    # from the hierarchy recorded at upload, instead of a run that fails when it starts.
    inverted = client.post(
        f"/api/v1/takes/{take['id']}/runs",
        json={"mapping": {"left_clavicle": "Spine", "left_upper_arm": "Hips"}},
        headers=alice[1],
    )
    assert inverted.status_code == 422, inverted.text
    assert inverted.json()["field"] == "mapping"
    assert "not its descendant" in inverted.json()["detail"]
    detail = client.get(f"/api/v1/takes/{take['id']}", headers=alice[1]).json()
    assert len(detail["runs"]) == 2


def test_shoot_names_lose_invisible_characters_as_take_names_do(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """A bidirectional override makes "gpj.exe" read as "exe.jpg"; take and reviewer names
    were cleaned of such characters, shoot names were stored and echoed as sent."""
    made = client.post("/api/v1/shoots", json={"name": "day\u202e one\u200b"}, headers=alice[1])
    assert made.status_code == 201, made.text
    assert made.json()["name"] == "day one"
    renamed = client.patch(
        f"/api/v1/shoots/{made.json()['id']}", json={"name": "\u2066day\ttwo"}, headers=alice[1]
    )
    assert renamed.json()["name"] == "day two"
    invisible = client.post("/api/v1/shoots", json={"name": "\u202e\u200b"}, headers=alice[1])
    assert invisible.status_code == 422, invisible.text


@pytest.mark.parametrize(
    ("body", "words"),
    [
        (b'{"name": "day \xff"}', "UTF-8"),
        (b'{"name": ' + b"[" * 100_000 + b"]" * 100_000 + b"}", "nested"),
    ],
)
def test_a_json_body_that_cannot_be_decoded_names_the_body(
    body: bytes, words: str, client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """Not UTF-8, or nested past the parser's depth: was a bare "There was an error parsing
    the body" (400) that said neither where nor why."""
    response = client.post(
        "/api/v1/shoots", content=body, headers={**alice[1], "Content-Type": "application/json"}
    )
    assert response.status_code == 422, response.text
    answer = response.json()
    assert answer["error"] == "ValidationError"
    assert answer["field"] == "body"
    assert words in answer["detail"]


@pytest.mark.parametrize(
    ("origin", "status"),
    [
        ("https://testserver", 403),  # the server answers http: another origin
        ("HTTPS://testserver", 403),
        ("ftp://testserver", 403),
        ("http://testserver", 201),
        ("HTTP://TestServer", 201),
    ],
)
def test_an_origin_of_another_scheme_is_cross_site(
    origin: str, status: int, client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """``Origin: https://host`` was accepted on an http server: the check compared the host
    alone, while an origin is scheme, host and port (a page on https://host is another site to
    http://host)."""
    headers = {**alice[1], "Origin": origin}
    response = client.post("/api/v1/shoots", json={"name": "day one"}, headers=headers)
    assert response.status_code == status, response.text
    if status == 403:
        assert response.json()["error"] == "ForbiddenError"
        assert client.get("/api/v1/shoots", headers=alice[1]).json() == []


@pytest.mark.parametrize(
    ("origin", "opens"), [("https://testserver", False), ("http://testserver", True)]
)
def test_a_stream_from_an_origin_of_another_scheme_is_refused(
    origin: str, opens: bool, client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """The stream answers ws:// (the page's http://); an https:// page is another site."""
    from starlette.websockets import WebSocketDisconnect

    headers = {**alice[1], "Origin": origin}
    if opens:
        with client.websocket_connect("/api/v1/stream/filter", headers=headers) as socket:
            socket.send_json({"fps": 30, "n_keypoints": 2})
            assert socket.receive_json()["ready"] is True
        return
    with (
        pytest.raises(WebSocketDisconnect) as refused,
        client.websocket_connect("/api/v1/stream/filter", headers=headers),
    ):
        pass
    assert refused.value.code == 1008


def raw_request(url: str, head: str, wait_s: float = 120.0) -> tuple[int, dict[str, Any]]:
    """Send only a request's head on a socket and read the answer: a server waiting for the
    body would never answer (the read then times out after ``wait_s``, a generous bound)."""
    address = urlsplit(url)
    with socket.create_connection((address.hostname, address.port), timeout=wait_s) as sock:
        sock.sendall(head.encode())
        status, _, body = read_answer(sock)
    return status, body


def bodiless_upload_head(url: str, path: str, token: str | None) -> str:
    """The head of a multipart POST to ``path`` announcing 100 MB (under both body limits)
    whose body is never sent: only an answer given before the body can come back."""
    head = f"POST {path} HTTP/1.1\r\nHost: {urlsplit(url).netloc}\r\n"
    if token is not None:
        head += f"Authorization: Bearer {token}\r\n"
    head += "Content-Type: multipart/form-data; boundary=b\r\n"
    return head + "Content-Length: 100000000\r\n\r\n"


@pytest.mark.parametrize("path", ["/api/v1/takes", "/api/v1/shoots/any/takes"])
def test_a_viewer_upload_is_refused_before_its_body(path: str, tmp_path: Path) -> None:
    """A viewer may not upload: the 403 used to come after the whole body (up to
    ``max_upload_mb``, or ``archive_max_unpacked_mb`` for an import) was received and spooled
    to disk. It now comes from the credential alone, as the 401 and the 429 do:
    a 100 MB Content-Length (under both limits) with no body sent gets its answer."""
    settings = make_settings("sqlite", tmp_path, allowed_hosts=["127.0.0.1"])
    app = create_app(settings)
    accounts = app.state.accounts
    viewer = accounts.add_user("vic", Role.VIEWER)
    token = accounts.issue(viewer.id, "api", timedelta(days=1)).token
    with serve(app) as url:
        status, body = raw_request(url, bodiless_upload_head(url, path, token))
    assert status == 403, body
    assert body["error"] == "ForbiddenError"
    assert "upload" in body["detail"]
    assert list((settings.data_dir / "incoming").iterdir()) == []


def test_an_import_into_a_missing_shoot_is_refused_before_its_body(tmp_path: Path) -> None:
    """The 404 of an import into a shoot that does not exist used to come after the whole
    body (up to ``archive_max_unpacked_mb``) was received; it now comes from the path alone,
    after the credential is checked."""
    settings = make_settings("sqlite", tmp_path, allowed_hosts=["127.0.0.1"])
    app = create_app(settings)
    accounts = app.state.accounts
    reviewer = accounts.add_user("rita", Role.REVIEWER)
    token = accounts.issue(reviewer.id, "api", timedelta(days=1)).token
    path = f"/api/v1/shoots/{'0' * 32}/takes"
    with serve(app) as url:
        status, body = raw_request(url, bodiless_upload_head(url, path, token))
        anonymous_status, _ = raw_request(url, bodiless_upload_head(url, path, None))
    assert status == 404, body
    assert body["error"] == "NotFoundError"
    assert "0" * 32 in body["detail"]
    assert anonymous_status == 401  # no word about shoots to a stranger
    assert list((settings.data_dir / "incoming").iterdir()) == []


OPEN_OPERATIONS = {("get", "/api/v1/health"), ("post", "/api/v1/auth/sign-in")}
"""The only operations an anonymous client may call on a server with users."""
VIEWER_CHANGES = {
    ("post", "/api/v1/auth/sign-out"),
    ("post", "/api/v1/tokens"),
    ("delete", "/api/v1/tokens/{token_id}"),
}
"""The only state-changing operations a viewer may call (its own session and tokens)."""


def test_every_operation_names_who_may_call_it(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """Every documented operation, called with ids that do not exist: anonymous gets 401
    (before a 404 could tell whether the id exists), a viewer 403 on anything that changes
    state, except the stated open operations and a viewer's own session and tokens. A new
    route without its ``require`` fails here."""
    _, viewer = bearer(client, "vic", Role.VIEWER)
    spec = client.get("/openapi.json").json()
    operations = [(m, p) for p, ops in spec["paths"].items() for m in ops]
    assert len(operations) > 30
    for method, path in operations:
        url = path.replace("{kind}", "csv")
        for name in ("take_id", "run_id", "shoot_id", "token_id", "name", "interval_id"):
            url = url.replace("{" + name + "}", "0")
        if (method, path) not in OPEN_OPERATIONS:
            anonymous = client.request(method.upper(), url, json={})
            assert anonymous.status_code == 401, (method, path, anonymous.text)
        if method != "get" and (method, path) not in VIEWER_CHANGES | OPEN_OPERATIONS:
            refused = client.request(method.upper(), url, json={}, headers=viewer)
            assert refused.status_code == 403, (method, path, refused.text)


def test_a_json_list_of_numbers_names_the_frame_at_fault(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """A JSON list of numbers is read as MediaPipe frames: it was a 422 reading "TypeError:
    object of type 'int' has no len()", naming no field."""
    response = client.post(
        "/api/v1/takes", files={"file": ("frames.json", b"[[], 1, 2]")}, headers=alice[1]
    )
    assert response.status_code == 422, response.text
    body = response.json()
    assert body["error"] == "ParseError"
    assert body["field"] == "frames[1]"
    assert "TypeError" not in body["detail"]


def test_a_frame_time_too_small_for_a_frame_rate_names_its_line(
    client: TestClient, alice: tuple[int, dict[str, str]]
) -> None:
    """``Frame Time: 5e-324`` is > 0 but its frame rate is infinite: the 422 came from the
    motion's own check ("Expected `fps` > 0, got inf") without the file's line."""
    data = SMALL_BVH.replace(b"Frame Time: 0.033333", b"Frame Time: 5e-324")
    response = client.post("/api/v1/takes", files={"file": ("tiny.bvh", data)}, headers=alice[1])
    assert response.status_code == 422, response.text
    body = response.json()
    assert body["error"] == "ParseError"
    assert body["line"] == 18
    assert "5e-324" in body["detail"]
