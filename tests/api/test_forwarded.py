"""Forwarded headers are believed only from the proxies named in ``trusted_proxies``.

uvicorn trusts ``X-Forwarded-For`` from 127.0.0.1 by default: thirty wrong passwords sent from
loopback with a new forged address each were never limited, the right one then succeeded, and
the audit log recorded the forged addresses. Served as ``mocapqa serve`` serves (a real
uvicorn with ``proxy_headers=False``), the connection's own address counts unless a proxy is
configured.
"""

from __future__ import annotations

from pathlib import Path

import httpx
import pytest
from tests.live_server import live_server

from mocapqa.api.routes.session import SIGN_INS_PER_MINUTE
from mocapqa.config import Settings
from mocapqa.store.accounts import Accounts
from mocapqa.store.repository import Repository
from mocapqa.store.roles import Role

ATTEMPTS = 30


def _settings(tmp_path: Path, **changes: object) -> Settings:
    settings = Settings(data_dir=tmp_path / "data", **changes)  # type: ignore[arg-type]
    settings.data_dir.mkdir(parents=True)
    repository = Repository(settings.resolved_database_url)
    try:
        Accounts(repository.engine).add_user("ana", Role.ADMIN, "a long enough password")
    finally:
        repository.close()
    return settings


def _forged_sign_ins(url: str) -> list[int]:
    codes = []
    with httpx.Client(base_url=url, timeout=60) as http:
        for n in range(ATTEMPTS):
            answer = http.post(
                "/api/v1/auth/sign-in",
                json={"name": "ana", "password": f"wrong {n}"},
                headers={"X-Forwarded-For": f"203.0.113.{n + 1}"},
            )
            codes.append(answer.status_code)
    return codes


def _audit_clients(settings: Settings) -> set[str]:
    repository = Repository(settings.resolved_database_url)
    try:
        entries, _ = Accounts(repository.engine).list_audit(500, 0)
    finally:
        repository.close()
    return {str(e["client"]) for e in entries if e["action"] == "sign_in_failed"}


def test_forged_forwarded_addresses_change_nothing_without_a_trusted_proxy(
    tmp_path: Path,
) -> None:
    settings = _settings(tmp_path)
    with live_server(settings) as url:
        codes = _forged_sign_ins(url)
        right = httpx.post(
            f"{url}/api/v1/auth/sign-in",
            json={"name": "ana", "password": "a long enough password"},
            headers={"X-Forwarded-For": "198.51.100.7"},
            timeout=60,
        )
    assert codes[:SIGN_INS_PER_MINUTE] == [401] * SIGN_INS_PER_MINUTE
    assert set(codes[SIGN_INS_PER_MINUTE:]) == {429}
    assert right.status_code == 429  # the limit holds for the address the server can vouch for
    assert _audit_clients(settings) == {"127.0.0.1"}


def test_a_trusted_proxy_s_forwarded_address_is_the_client(tmp_path: Path) -> None:
    settings = _settings(tmp_path, trusted_proxies=["127.0.0.0/8"])
    with live_server(settings) as url:
        codes = _forged_sign_ins(url)
    assert set(codes) == {401}  # thirty clients behind the proxy, one attempt each
    assert _audit_clients(settings) == {f"203.0.113.{n + 1}" for n in range(ATTEMPTS)}


def test_a_trusted_proxy_that_is_not_an_address_is_refused_at_start(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="trusted_proxies"):
        Settings(data_dir=tmp_path, trusted_proxies=["proxy.example.org"])
