"""The Host check's matching: names, ``*.domain`` patterns and IPv6 literals as addresses."""

from __future__ import annotations

import pytest
from starlette.responses import PlainTextResponse
from starlette.testclient import TestClient
from starlette.types import Receive, Scope, Send

from mocapqa.api.host_check import HostCheck, host_name, normal_host


async def _app(scope: object, receive: object, send: object) -> None:  # never called here
    raise AssertionError("not reached")


@pytest.mark.parametrize(
    ("entry", "normal"),
    [
        ("::1", "[::1]"),
        ("[::1]", "[::1]"),
        ("0:0:0:0:0:0:0:1", "[::1]"),
        ("[FE80::A]", "[fe80::a]"),
        ("Example.ORG", "example.org"),
        ("127.0.0.1", "127.0.0.1"),
        ("*.example.org", "*.example.org"),
    ],
)
def test_allowed_entries_are_compared_in_one_form(entry: str, normal: str) -> None:
    assert normal_host(entry) == normal


@pytest.mark.parametrize(
    ("header", "name"),
    [
        ("[::1]:8000", "[::1]"),
        ("[::1]", "[::1]"),
        ("[0::1]:", "[::1]"),
        ("localhost:8000", "localhost"),
        ("EXAMPLE.org", "example.org"),
        ("[evil]", None),
        ("[::1", None),
        ("::1", None),
        ("[::1]:80:80", None),
        ("[::1]x", None),
        ("host:port", None),
        ("a b", None),
        ("", None),
        (None, None),
    ],
)
def test_host_header_is_parsed_or_refused(header: str | None, name: str | None) -> None:
    assert host_name(header) == name


def test_host_check_matches_ipv6_names_and_domains() -> None:
    check = HostCheck(_app, ["::1", "mocapqa.example.org", "*.studio.example"])
    allowed = ["[::1]:8000", "[0:0::1]", "mocapqa.example.org:443", "a.studio.example"]
    refused = ["[::2]", "[evil]:8000", "example.org", "studio.example.evil", "::1", None]
    assert [check.allows(h) for h in allowed] == [True] * len(allowed)
    assert [check.allows(h) for h in refused] == [False] * len(refused)
    assert HostCheck(_app, ["*"]).allows("anything.example:1")


@pytest.mark.parametrize("entry", ["*example.org", "a.*.org", "**"])
def test_host_patterns_other_than_a_leading_star_dot_are_refused(entry: str) -> None:
    with pytest.raises(ValueError, match=r"\*\.example\.org"):
        HostCheck(_app, [entry])


async def _ok(scope: Scope, receive: Receive, send: Send) -> None:
    await PlainTextResponse("ok")(scope, receive, send)


@pytest.mark.parametrize(
    "hosts",
    [
        ["testserver", "testserver"],  # both allowed: still two answers to "which server?"
        ["testserver", "evil.example"],  # the first was used, the second never checked
        ["evil.example", "testserver"],
    ],
)
def test_two_host_headers_are_400(hosts: list[str]) -> None:
    """Two ``Host`` headers in one request were accepted, the first used: a proxy or log in
    front of the server may have read the other."""
    client = TestClient(HostCheck(_ok, ["testserver"]))
    response = client.get("/", headers=[("host", host) for host in hosts])
    assert response.status_code == 400, response.text
    assert response.json()["error"] == "HostError"
    assert f"one Host header, got {len(hosts)}" in response.json()["detail"]
    assert client.get("/", headers=[("host", "testserver")]).status_code == 200
