"""Accounts and roles through the API: the role × endpoint matrix (SQLite and PostgreSQL),
CSRF on cookie requests, the one-time sign-in link, and the audit log of every action."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from starlette.requests import HTTPConnection
from tests.api.conftest import make_settings

from mocapqa.api.app import create_app
from mocapqa.api.auth import CSRF_COOKIE, CSRF_HEADER, SESSION_COOKIE, quota_key_before_body
from mocapqa.api.routes.session import sign_in_link
from mocapqa.config import Settings
from mocapqa.errors import ConflictError
from mocapqa.render.service import RenderService
from mocapqa.store.accounts import Accounts
from mocapqa.store.roles import Role
from mocapqa.store.shoots import ShootStore

ROLES = {"admin": Role.ADMIN, "viewer": Role.VIEWER, "rev1": Role.REVIEWER, "rev2": Role.REVIEWER}
PASSWORD = "correct horse battery"


@pytest.fixture
def team(
    settings: Settings, renderer: RenderService
) -> Iterator[tuple[TestClient, dict[str, dict[str, str]]]]:
    """An app with an admin, a viewer and two reviewers, and each one's Bearer header."""
    settings = settings.model_copy(update={"job_workers": 1})
    with TestClient(create_app(settings, renderer=renderer)) as client:
        accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
        headers = {}
        for name, role in ROLES.items():
            user = accounts.add_user(name, role, PASSWORD)
            token = accounts.issue(user.id, "api", __import__("datetime").timedelta(days=1))
            headers[name] = {"Authorization": f"Bearer {token.token}"}
        headers["anonymous"] = {}
        yield client, headers


def _upload(client: TestClient, path: Path, headers: dict[str, str]) -> Any:
    with path.open("rb") as handle:
        return client.post("/api/v1/takes", files={"file": (path.name, handle)}, headers=headers)


def test_role_endpoint_matrix(
    team: tuple[TestClient, dict[str, dict[str, str]]], cmu_walk: Path
) -> None:
    client, headers = team
    mine = _upload(client, cmu_walk, headers["rev1"])
    assert mine.status_code == 201, mine.text
    take = mine.json()["id"]
    assert mine.json()["owner_id"] is not None
    run = mine.json()["run_id"]
    who = ["anonymous", "viewer", "rev1", "rev2", "admin"]
    # (method, path, body) -> expected status for each of `who`
    matrix: list[tuple[str, str, Any, list[int | None]]] = [
        ("GET", "/health", None, [200, 200, 200, 200, 200]),
        ("GET", "/me", None, [401, 200, 200, 200, 200]),
        ("GET", "/takes", None, [401, 200, 200, 200, 200]),
        ("GET", f"/takes/{take}", None, [401, 200, 200, 200, 200]),
        ("GET", f"/takes/{take}/reviews", None, [401, 200, 200, 200, 200]),
        ("GET", f"/runs/{run}", None, [401, 200, 200, 200, 200]),
        ("GET", "/filters", None, [401, 200, 200, 200, 200]),
        ("POST", f"/takes/{take}/reviews", {"status": "approved"}, [401, 403, 201, 201, 201]),
        ("POST", f"/takes/{take}/runs", {}, [401, 403, 201, 201, 201]),
        ("GET", "/users", None, [401, 403, 403, 403, 200]),
        ("POST", "/users", {"name": "x", "role": "viewer"}, [401, 403, 403, 403, 201]),
        ("PATCH", "/users/viewer", {"role": "viewer"}, [401, 403, 403, 403, 200]),
        ("GET", "/audit", None, [401, 403, 403, 403, 200]),
        ("GET", "/tokens", None, [401, 200, 200, 200, 200]),
        ("POST", "/tokens", {"expires_days": 1}, [401, 201, 201, 201, 201]),
        # rev2 is a reviewer, but not the take's owner (rev1 and admin: checked below)
        ("DELETE", f"/takes/{take}", None, [401, 403, None, 403, None]),
    ]
    failures = []
    for method, path, body, expected in matrix:
        for name, status in zip(who, expected, strict=True):
            if status is None:
                continue
            answer = client.request(method, f"/api/v1{path}", json=body, headers=headers[name])
            if answer.status_code != status:
                failures.append(f"{method} {path} as {name}: {answer.status_code} != {status}")
    assert not failures, "\n".join(failures)
    assert (
        client.get("/api/v1/takes", headers=headers["anonymous"]).headers["www-authenticate"]
        == "Bearer"
    )
    # the reviewer of a review is who is signed in, whatever the body says
    review = client.post(
        f"/api/v1/takes/{take}/reviews",
        json={"status": "rejected", "reviewer": "somebody else"},
        headers=headers["rev2"],
    )
    assert review.json()["reviewer"] == "rev2"
    # the owner deletes their own take; an admin deletes anyone's
    assert client.delete(f"/api/v1/takes/{take}", headers=headers["rev1"]).status_code == 204
    other = _upload(client, cmu_walk, headers["rev2"]).json()["id"]
    assert client.delete(f"/api/v1/takes/{other}", headers=headers["rev1"]).status_code == 403
    assert client.delete(f"/api/v1/takes/{other}", headers=headers["admin"]).status_code == 204
    assert _upload(client, cmu_walk, headers["viewer"]).status_code == 403
    assert _upload(client, cmu_walk, headers["anonymous"]).status_code == 401
    # shoots: read by everyone signed in, made by reviewers (test_shoot_owner_matrix: the rest)
    day = {"name": "day1"}
    assert client.get("/api/v1/shoots", headers=headers["anonymous"]).status_code == 401
    assert client.get("/api/v1/shoots", headers=headers["viewer"]).status_code == 200
    assert client.post("/api/v1/shoots", json=day, headers=headers["viewer"]).status_code == 403
    assert client.post("/api/v1/shoots", json=day, headers=headers["rev1"]).status_code == 201


def test_shoot_owner_matrix(
    team: tuple[TestClient, dict[str, dict[str, str]]], cmu_walk: Path
) -> None:
    """A shoot is renamed and deleted by its maker or an admin; a second reviewer may read it
    and import into it (owning what it imports), but not rename or delete it."""
    client, headers = team
    made = client.post("/api/v1/shoots", json={"name": "day1"}, headers=headers["rev1"])
    assert made.status_code == 201, made.text
    shoot = made.json()["id"]
    rev1 = client.get("/api/v1/me", headers=headers["rev1"]).json()["user_id"]
    assert made.json()["owner_id"] == rev1
    with cmu_walk.open("rb") as handle:
        part = [("files", (cmu_walk.name, handle.read()))]
    imported = client.post(f"/api/v1/shoots/{shoot}/takes", files=part, headers=headers["rev2"])
    assert imported.status_code == 201, imported.text
    take = imported.json()["created"][0]["take_id"]
    who = ["anonymous", "viewer", "rev1", "rev2", "admin"]
    base = f"/api/v1/shoots/{shoot}"
    matrix: list[tuple[str, str, Any, list[int | None]]] = [
        ("GET", base, None, [401, 200, 200, 200, 200]),
        ("GET", f"{base}/takes", None, [401, 200, 200, 200, 200]),
        ("PATCH", base, {"name": "day1"}, [401, 403, 200, 403, 200]),
        ("DELETE", f"{base}?confirm=day1", None, [401, 403, None, 403, None]),
        # the importer owns the take it imported; the shoot's owner does not
        ("DELETE", f"/api/v1/takes/{take}", None, [401, 403, 403, None, None]),
    ]
    failures = []
    for method, path, body, expected in matrix:
        for name, status in zip(who, expected, strict=True):
            if status is None:
                continue
            answer = client.request(method, path, json=body, headers=headers[name])
            if answer.status_code != status:
                failures.append(f"{method} {path} as {name}: {answer.status_code} != {status}")
    assert not failures, "\n".join(failures)
    assert (
        client.get(f"/api/v1/takes/{take}", headers=headers["rev2"]).json()["owner_id"]
        == (client.get("/api/v1/me", headers=headers["rev2"]).json()["user_id"])
    )
    # the owner deletes the shoot, with every take in it
    assert client.delete(f"{base}?confirm=day1", headers=headers["rev1"]).status_code == 204
    assert client.get(f"/api/v1/takes/{take}", headers=headers["admin"]).status_code == 404
    # an admin deletes anyone's shoot; a shoot without an owner (made before owners) is theirs
    other = client.post("/api/v1/shoots", json={"name": "day2"}, headers=headers["rev2"]).json()
    assert (
        client.delete(
            f"/api/v1/shoots/{other['id']}?confirm=day2", headers=headers["admin"]
        ).status_code
        == 204
    )
    orphan = ShootStore(client.app.state.services.repository.engine).create("day3")  # type: ignore[attr-defined]
    assert orphan["owner_id"] is None
    for name in ("rev1", "rev2"):
        path = f"/api/v1/shoots/{orphan['id']}"
        assert client.patch(path, json={"name": "x"}, headers=headers[name]).status_code == 403
        assert client.delete(f"{path}?confirm=day3", headers=headers[name]).status_code == 403
    path = f"/api/v1/shoots/{orphan['id']}?confirm=day3"
    assert client.delete(path, headers=headers["admin"]).status_code == 204
    log = client.get("/api/v1/audit?limit=500", headers=headers["admin"]).json()["items"]
    actions = [e["action"] for e in log]
    assert {"shoot_create", "shoot_rename", "shoot_delete"} <= set(actions)


def test_tokens_are_revocable_and_expire(
    team: tuple[TestClient, dict[str, dict[str, str]]],
) -> None:
    client, headers = team
    made = client.post("/api/v1/tokens", json={"name": "ci"}, headers=headers["viewer"]).json()
    mine = {"Authorization": f"Bearer {made['token']}"}
    assert client.get("/api/v1/me", headers=mine).json()["name"] == "viewer"
    listed = client.get("/api/v1/tokens", headers=mine).json()
    assert "token" not in listed[0]
    assert listed[0]["id"] == made["id"]
    # another non-admin cannot revoke it; its owner can
    assert client.delete(f"/api/v1/tokens/{made['id']}", headers=headers["rev1"]).status_code == 403
    assert client.delete(f"/api/v1/tokens/{made['id']}", headers=mine).status_code == 204
    assert client.get("/api/v1/me", headers=mine).status_code == 401
    accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
    user = accounts.get_user("viewer")
    expired = accounts.issue(user.id, "api", __import__("datetime").timedelta(seconds=-1))
    answer = client.get("/api/v1/me", headers={"Authorization": f"Bearer {expired.token}"})
    assert answer.status_code == 401
    forged = made["token"][:-4] + "AAAA"
    assert (
        client.get("/api/v1/me", headers={"Authorization": f"Bearer {forged}"}).status_code == 401
    )
    # disabling a user stops their tokens
    client.patch("/api/v1/users/rev2", json={"disabled": True}, headers=headers["admin"])
    assert client.get("/api/v1/me", headers=headers["rev2"]).status_code == 401
    # the last admin stays
    answer = client.patch("/api/v1/users/admin", json={"role": "viewer"}, headers=headers["admin"])
    assert answer.status_code == 409


def test_cookie_requests_need_the_csrf_token(
    team: tuple[TestClient, dict[str, dict[str, str]]], cmu_walk: Path
) -> None:
    client, headers = team
    take = _upload(client, cmu_walk, headers["rev1"]).json()["id"]
    bad = client.post("/api/v1/auth/sign-in", json={"name": "rev2", "password": "nope"})
    assert bad.status_code == 401
    assert SESSION_COOKIE_NAME not in client.cookies
    signed = client.post("/api/v1/auth/sign-in", json={"name": "rev2", "password": PASSWORD})
    assert signed.status_code == 200, signed.text
    cookie = signed.headers.get_list("set-cookie")
    session = next(c for c in cookie if c.startswith(SESSION_COOKIE_NAME))
    assert "HttpOnly" in session
    assert "SameSite=strict" in session
    assert client.get("/api/v1/me").json()["name"] == "rev2"
    review = {"status": "approved"}
    assert client.post(f"/api/v1/takes/{take}/reviews", json=review).status_code == 403
    wrong = {CSRF_HEADER: "x" * 43}
    assert (
        client.post(f"/api/v1/takes/{take}/reviews", json=review, headers=wrong).status_code == 403
    )
    right = {CSRF_HEADER: client.cookies[CSRF_COOKIE]}
    answer = client.post(f"/api/v1/takes/{take}/reviews", json=review, headers=right)
    assert answer.status_code == 201
    assert answer.json()["reviewer"] == "rev2"
    assert client.post("/api/v1/auth/sign-out", headers=right).status_code == 204
    client.cookies.clear()
    client.cookies.set(SESSION_COOKIE_NAME, session.split(";")[0].split("=", 1)[1])
    assert client.get("/api/v1/me").status_code == 401  # the old session was ended


SESSION_COOKIE_NAME = "mocapqa_session"


def test_sign_in_link_works_once(team: tuple[TestClient, dict[str, dict[str, str]]]) -> None:
    client, _ = team
    accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
    link = sign_in_link(accounts, accounts.get_user("admin"), "http://testserver")
    first = client.get(link, follow_redirects=False)
    assert first.status_code == 303
    assert first.headers["location"] == "/"
    assert client.get("/api/v1/me").json()["name"] == "admin"
    client.cookies.clear()
    again = client.get(link, follow_redirects=False)
    assert again.status_code == 303
    assert "refused" in again.headers["location"]
    assert client.get("/api/v1/me").status_code == 401


def test_every_action_is_audited(
    team: tuple[TestClient, dict[str, dict[str, str]]], cmu_walk: Path
) -> None:
    client, headers = team
    take = _upload(client, cmu_walk, headers["rev1"]).json()["id"]
    client.post(f"/api/v1/takes/{take}/runs", json={}, headers=headers["rev1"])
    client.post(
        f"/api/v1/takes/{take}/reviews", json={"status": "approved"}, headers=headers["rev1"]
    )
    client.delete(f"/api/v1/takes/{take}", headers=headers["admin"])
    client.post("/api/v1/auth/sign-in", json={"name": "rev1", "password": "wrong"})
    client.post("/api/v1/auth/sign-in", json={"name": "rev1", "password": PASSWORD})
    client.cookies.clear()
    client.patch("/api/v1/users/viewer", json={"role": "reviewer"}, headers=headers["admin"])
    made = client.post("/api/v1/tokens", json={}, headers=headers["viewer"]).json()
    client.delete(f"/api/v1/tokens/{made['id']}", headers=headers["admin"])
    page = client.get("/api/v1/audit?limit=100", headers=headers["admin"]).json()
    entries = {(e["action"], e["user_name"], e["target"]) for e in page["items"]}
    expected = {
        ("upload", "rev1", take),
        ("run", "rev1", take),
        ("review", "rev1", take),
        ("delete", "admin", take),
        ("sign_in_failed", None, "rev1"),
        ("sign_in", "rev1", "rev1"),
        ("user_change", "admin", "viewer"),
        ("token_create", "viewer", made["id"]),
        ("token_revoke", "admin", made["id"]),
    }
    assert expected <= entries, expected - entries
    assert all(e["client"] == "testclient" for e in page["items"])
    assert page["total"] == len(page["items"])
    # read only: no route writes or deletes entries
    for method in ("POST", "PUT", "PATCH", "DELETE"):
        assert client.request(method, "/api/v1/audit", headers=headers["admin"]).status_code == 405


def test_open_without_users(tmp_path: Path, renderer: RenderService, cmu_walk: Path) -> None:
    settings = make_settings("sqlite", tmp_path)
    with TestClient(create_app(settings, renderer=renderer)) as client:
        me = client.get("/api/v1/me").json()
        assert me["via"] == "open"
        assert me["role"] == "admin"
        assert _upload(client, cmu_walk, {}).status_code == 201
        accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
        accounts.add_user("first", Role.ADMIN)
        assert client.get("/api/v1/takes").status_code == 401
        refused = _upload(client, cmu_walk, {})  # refused before its body is read
        assert refused.status_code == 401
        assert refused.headers["www-authenticate"] == "Bearer"
        assert refused.json()["error"] == "AuthenticationError"


def test_stream_needs_a_user(team: tuple[TestClient, dict[str, dict[str, str]]]) -> None:
    from starlette.testclient import WebSocketDenialResponse

    client, headers = team
    with (
        pytest.raises(WebSocketDenialResponse) as refused,
        client.websocket_connect("/api/v1/stream/filter"),
    ):
        pass
    assert refused.value.status_code == 401
    with client.websocket_connect("/api/v1/stream/filter", headers=headers["viewer"]) as ws:
        ws.send_json({"fps": 30, "n_keypoints": 3})
        assert ws.receive_json()["ready"] is True


def test_password_guessing_is_slowed(team: tuple[TestClient, dict[str, dict[str, str]]]) -> None:
    client, headers = team
    wrong = {"name": "rev1", "password": "guess"}
    answers = [client.post("/api/v1/auth/sign-in", json=wrong).status_code for _ in range(11)]
    assert answers == [401] * 10 + [429]
    right = client.post("/api/v1/auth/sign-in", json={"name": "rev1", "password": PASSWORD})
    assert right.status_code == 429
    assert int(right.headers["retry-after"]) >= 1
    page = client.get("/api/v1/audit", headers=headers["admin"]).json()
    assert sum(e["action"] == "sign_in_failed" for e in page["items"]) == 12


def test_quota_key_before_body_names_the_user_of_a_valid_credential_only(
    team: tuple[TestClient, dict[str, dict[str, str]]],
) -> None:
    """The upload quotas' key, found before the body: the user of a live token or session,
    None for what the routes refuse with 401; a read-only lookup (``last_used_at`` stays)."""
    client, headers = team
    accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
    day = __import__("datetime").timedelta(days=1)
    rev1 = accounts.get_user("rev1")
    session = accounts.issue(rev1.id, "session", day, with_csrf=True).token
    expired = accounts.issue(rev1.id, "api", -day).token
    revoked = accounts.issue(rev1.id, "api", day)
    accounts.revoke(revoked.id)
    rev2_token = headers["rev2"]["Authorization"].split()[1]
    accounts.update_user("rev2", disabled=True)

    def key(header: tuple[bytes, bytes] | None) -> str:
        scope = {
            "type": "http",
            "method": "POST",
            "path": "/api/v1/takes",
            "headers": [header] if header else [],
            "client": ("10.1.2.3", 5000),
        }
        return quota_key_before_body(HTTPConnection(scope), accounts)

    def bearer(token: str) -> tuple[bytes, bytes]:
        return (b"authorization", f"Bearer {token}".encode())

    used_before = {t["id"]: t["last_used_at"] for t in accounts.list_tokens()}
    assert key(bearer(headers["rev1"]["Authorization"].split()[1])) == f"user:{rev1.id}"
    assert key((b"cookie", f"{SESSION_COOKIE}={session}".encode())) == f"user:{rev1.id}"
    # what the routes refuse with 401 is refused before the body (None)
    assert key(None) is None
    for refused in (expired, revoked.token, rev2_token, session, "mqa_nonsense", ""):
        assert key(bearer(refused)) is None, refused
    assert key((b"authorization", b"Basic eDp5")) is None
    assert key((b"cookie", f"{SESSION_COOKIE}={expired}".encode())) is None
    assert {t["id"]: t["last_used_at"] for t in accounts.list_tokens()} == used_before


def test_two_admins_demoting_each_other_leave_one(
    team: tuple[TestClient, dict[str, dict[str, str]]],
) -> None:
    import threading

    client, _ = team
    accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
    accounts.add_user("second", Role.ADMIN, PASSWORD)
    # A disabled admin may be demoted: it is not the enabled admin that must remain.
    accounts.add_user("idle", Role.ADMIN, PASSWORD)
    accounts.update_user("idle", disabled=True)
    assert accounts.update_user("idle", role=Role.VIEWER).role is Role.VIEWER
    # Both enabled admins demote themselves at once, many times over: one always remains.
    for _ in range(10):
        start = threading.Barrier(2)
        outcomes: list[str] = []

        def demote(name: str, start: threading.Barrier, outcomes: list[str]) -> None:
            start.wait()
            try:
                accounts.update_user(name, role=Role.VIEWER)
                outcomes.append("demoted")
            except ConflictError:
                outcomes.append("refused")

        threads = [
            threading.Thread(target=demote, args=(n, start, outcomes)) for n in ("admin", "second")
        ]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        admins = [u for u in accounts.list_users() if u.role is Role.ADMIN and not u.disabled]
        assert len(admins) == 1, outcomes
        assert sorted(outcomes) == ["demoted", "refused"]
        # Restore the second admin for the next round.
        for name in ("admin", "second"):
            accounts.update_user(name, role=Role.ADMIN)


def test_unknown_fields_and_admin_only_listings_are_refused_not_ignored(
    team: tuple[TestClient, dict[str, dict[str, str]]],
) -> None:
    client, headers = team
    # A token request naming another user used to mint one for the caller.
    minted = client.post(
        "/api/v1/tokens", json={"name": "ci", "user": "admin"}, headers=headers["rev1"]
    )
    assert minted.status_code == 422
    assert minted.json()["field"] == "body.user"
    made = client.post(
        "/api/v1/users", json={"name": "new", "disabled": True}, headers=headers["admin"]
    )
    assert made.status_code == 422
    assert client.get("/api/v1/users", headers=headers["admin"]).json()[-1]["name"] != "new"
    # Everyone's tokens are an admin's listing: a viewer asking gets 403, not their own list.
    assert client.get("/api/v1/tokens?everyone=true", headers=headers["viewer"]).status_code == 403
    assert client.get("/api/v1/tokens?everyone=true", headers=headers["admin"]).status_code == 200


def test_names_that_only_look_alike_are_one_name(
    team: tuple[TestClient, dict[str, dict[str, str]]],
) -> None:
    client, headers = team
    accounts: Accounts = client.app.state.accounts  # type: ignore[attr-defined]
    # "ADMIN" beside "admin" would read as one person in the audit log.
    with pytest.raises(ConflictError, match="exists as 'admin'"):
        accounts.add_user("ADMIN", Role.VIEWER, PASSWORD)
    # A shoot name typed composed and decomposed is one name.
    composed = client.post("/api/v1/shoots", json={"name": "Ünï"}, headers=headers["admin"])
    assert composed.status_code == 201
    decomposed = client.post(
        "/api/v1/shoots", json={"name": "U\u0308ni\u0308"}, headers=headers["admin"]
    )
    assert decomposed.status_code == 409
    # So is one typed in another case, non-ASCII letters included (SQLite's lower() is ASCII).
    cased = client.post("/api/v1/shoots", json={"name": "üNÏ"}, headers=headers["admin"])
    assert cased.status_code == 409
    assert "exists as 'Ünï'" in cased.json()["detail"]
    other = client.post("/api/v1/shoots", json={"name": "Day 2"}, headers=headers["admin"])
    assert other.status_code == 201
    renamed = client.patch(
        f"/api/v1/shoots/{other.json()['id']}", json={"name": "ünï"}, headers=headers["admin"]
    )
    assert renamed.status_code == 409
    # A shoot may change the case of its own name.
    recased = client.patch(
        f"/api/v1/shoots/{other.json()['id']}", json={"name": "DAY 2"}, headers=headers["admin"]
    )
    assert recased.status_code == 200
    assert recased.json()["name"] == "DAY 2"


def test_a_shoot_asked_for_by_a_decomposed_name_is_found(tmp_path: Path) -> None:
    from mocapqa.store.repository import Repository

    store = ShootStore(Repository(f"sqlite:///{tmp_path / 'db.sqlite3'}").engine)
    made = store.ensure("Ünï")
    assert store.ensure("U\u0308ni\u0308")["id"] == made["id"]
    assert store.ensure("üNÏ")["id"] == made["id"]
    assert store.ensure("üNÏ")["name"] == "Ünï"
