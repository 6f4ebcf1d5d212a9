"""Checking a credential is a read; its last use is written later, coalesced.

Before, every authenticated request ran ``UPDATE tokens SET last_used_at`` in its own write
transaction, so parallel reads queued behind SQLite's one write lock and answered 500
("database is locked").
"""

from __future__ import annotations

from datetime import timedelta
from typing import Any

import pytest
from sqlalchemy import event

from mocapqa.errors import AuthenticationError
from mocapqa.store.accounts import Accounts
from mocapqa.store.repository import Repository
from mocapqa.store.roles import Role


def _writes_during(repository: Repository, action: Any) -> list[str]:
    statements: list[str] = []

    def seen(conn: Any, cursor: Any, statement: str, *args: Any) -> None:
        statements.append(statement)

    event.listen(repository.engine, "before_cursor_execute", seen)
    try:
        action()
    finally:
        event.remove(repository.engine, "before_cursor_execute", seen)
    verbs = ("INSERT", "UPDATE", "DELETE")
    return [s for s in statements if s.lstrip().upper().startswith(verbs)]


def _last_used(accounts: Accounts, token_id: str) -> Any:
    return next(t["last_used_at"] for t in accounts.list_tokens() if t["id"] == token_id)


def test_checking_a_token_writes_nothing_and_its_use_is_recorded_once_a_minute(
    repository: Repository,
) -> None:
    accounts = Accounts(repository.engine)
    user = accounts.add_user("viewer", Role.VIEWER)
    issued = accounts.issue(user.id, "api", timedelta(days=1))

    writes = _writes_during(
        repository, lambda: [accounts.verify(issued.token, "api") for _ in range(20)]
    )

    assert writes == []
    assert accounts.last_use.pending() <= 1  # twenty uses in a minute: one to record
    accounts.last_use.flush()
    first = _last_used(accounts, issued.id)
    assert first is not None
    accounts.verify(issued.token, "api")
    accounts.last_use.flush()
    assert _last_used(accounts, issued.id) == first  # within the minute: not written again


def test_a_sign_in_link_is_still_consumed_once(repository: Repository) -> None:
    accounts = Accounts(repository.engine)
    user = accounts.add_user("reviewer", Role.REVIEWER)
    link = accounts.issue(user.id, "link", timedelta(minutes=15))
    found, _ = accounts.verify(link.token, "link", consume=True)
    assert found.name == "reviewer"
    with pytest.raises(AuthenticationError):
        accounts.verify(link.token, "link", consume=True)
