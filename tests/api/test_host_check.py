"""The Host check's matching: names, ``*.domain`` patterns and IPv6 literals as addresses."""

from __future__ import annotations

import pytest

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
