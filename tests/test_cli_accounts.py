"""The fixed contract of ``mocapqa users`` and ``mocapqa tokens``, run as a script would: a
separate process with ``MOCAPQA_DATA_DIR`` naming the store, the token taken from the last line
of stdout and used as ``Authorization: Bearer`` against the API on the same store."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from fastapi.testclient import TestClient

from mocapqa.api.app import create_app
from mocapqa.config import Settings

BACKEND = Path(__file__).resolve().parents[1] / "backend"


def mocapqa(data_dir: Path, *args: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "MOCAPQA_DATA_DIR": str(data_dir), "PYTHONPATH": str(BACKEND)}
    env.pop("MOCAPQA_DATABASE_URL", None)
    return subprocess.run(
        [sys.executable, "-m", "mocapqa.cli.main", *args],
        env=env,
        input=stdin,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_users_and_tokens_contract(tmp_path: Path) -> None:
    data = tmp_path / "store"
    assert mocapqa(data, "users", "add", "ci", "--role", "reviewer").returncode == 0
    added = mocapqa(
        data, "users", "add", "boss", "--role", "admin", "--password-stdin", stdin="pw\n"
    )
    assert added.returncode == 0, added.stderr
    assert mocapqa(data, "users", "add", "ci", "--role", "viewer").returncode != 0  # taken
    assert mocapqa(data, "users", "add", "x", "--role", "owner").returncode != 0  # no such role
    listed = mocapqa(data, "users", "list").stdout.splitlines()
    assert listed == ["boss\tadmin\tenabled\tpassword", "ci\treviewer\tenabled\ttokens only"]
    made = mocapqa(data, "tokens", "create", "--user", "ci", "--expires-days", "2")
    assert made.returncode == 0, made.stderr
    token = made.stdout.strip().splitlines()[-1]
    settings = Settings(data_dir=data, allowed_hosts=["testserver"])
    with TestClient(create_app(settings)) as client:
        bearer = {"Authorization": f"Bearer {token}"}
        me = client.get("/api/v1/me", headers=bearer).json()
        assert (me["name"], me["role"]) == ("ci", "reviewer")
        assert client.get("/api/v1/takes", headers=bearer).status_code == 200
        assert client.get("/api/v1/takes").status_code == 401
        assert mocapqa(data, "users", "set-role", "ci", "viewer").returncode == 0
        assert client.get("/api/v1/me", headers=bearer).json()["role"] == "viewer"
        token_id = token.split("_")[1]
        assert mocapqa(data, "tokens", "revoke", token_id).returncode == 0
        assert client.get("/api/v1/me", headers=bearer).status_code == 401
        second = mocapqa(data, "tokens", "create", "--user", "ci").stdout.splitlines()[-1]
        assert mocapqa(data, "users", "disable", "ci").returncode == 0
        answer = client.get("/api/v1/me", headers={"Authorization": f"Bearer {second}"})
        assert answer.status_code == 401
        actions = [e["action"] for e in client.app.state.accounts.list_audit(100, 0)[0]]  # type: ignore[attr-defined]
    assert actions.count("user_add") == 2
    assert "token_revoke" in actions


def test_serve_refuses_a_public_address_without_users(tmp_path: Path) -> None:
    done = mocapqa(tmp_path / "store", "serve", "--host", "0.0.0.0", "--port", "1")
    assert done.returncode != 0
    assert "Expected a configured user before serving on 0.0.0.0" in done.stderr


def test_first_loopback_start_makes_an_admin_and_a_link(tmp_path: Path) -> None:
    from mocapqa.cli.serve import _sign_in

    os.environ["MOCAPQA_DATA_DIR"] = str(tmp_path / "store")
    try:
        link = _sign_in("127.0.0.1", 8123)
    finally:
        del os.environ["MOCAPQA_DATA_DIR"]
    assert link is not None
    assert link.startswith("http://127.0.0.1:8123/api/v1/auth/link/mqa_")
    users = mocapqa(tmp_path / "store", "users", "list").stdout.splitlines()
    assert users == ["admin\tadmin\tenabled\ttokens only"]
    settings = Settings(data_dir=tmp_path / "store", allowed_hosts=["testserver"])
    with TestClient(create_app(settings)) as client:
        path = link.split("8123", 1)[1]
        assert client.get(path, follow_redirects=False).headers["location"] == "/"
        assert client.get("/api/v1/me").json()["name"] == "admin"


def test_a_token_for_a_disabled_user_is_refused(tmp_path: Path) -> None:
    """It was printed (exit 0) but never signed in: disabling revokes a user's tokens and
    refuses new sign-ins."""
    data = tmp_path / "store"
    assert mocapqa(data, "users", "add", "gone", "--role", "reviewer").returncode == 0
    assert mocapqa(data, "users", "disable", "gone").returncode == 0
    made = mocapqa(data, "tokens", "create", "--user", "gone")
    assert made.returncode != 0
    assert "Expected an enabled user" in made.stderr, made.stderr
    assert "disabled" in made.stderr
    assert "mqa_" not in made.stdout
    assert mocapqa(data, "tokens", "create", "--user", "nobody").returncode != 0
