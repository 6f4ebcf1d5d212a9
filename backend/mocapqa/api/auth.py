"""Who is asking, and whether they may: the principal of a request and the role checks.

A request names its user with ``Authorization: Bearer TOKEN`` (a personal token) or with the
browser's session cookie. A state-changing request (POST, PUT, PATCH, DELETE) made with the
cookie must also carry the session's CSRF token in the ``X-CSRF-Token`` header (the double
submit: the token is also in a cookie the page's script can read, which another site cannot);
Bearer requests are exempt, as a browser never adds that header by itself.

While the server has no user at all, every request is served as an anonymous admin (the open
embedded default); once a user exists, a request without valid credentials gets 401.

Each route names the :class:`~mocapqa.store.roles.Action` it performs with :func:`require`;
:data:`~mocapqa.api.app.ROUTERS` gives every router its read requirement. Deleting a take, and
renaming or deleting a shoot, also needs :func:`require_owner`: its owner, or a role allowed
``delete_any``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated

from fastapi import Depends, Request
from starlette.requests import HTTPConnection

from mocapqa.api.app_state import app_state
from mocapqa.errors import AuthenticationError, ForbiddenError
from mocapqa.store.accounts import Accounts, User
from mocapqa.store.roles import Action, Role, allows

__all__ = [
    "CSRF_COOKIE",
    "CSRF_HEADER",
    "SESSION_COOKIE",
    "AccountsDep",
    "Principal",
    "PrincipalDep",
    "audit",
    "client_address",
    "get_accounts",
    "get_principal",
    "quota_key",
    "quota_key_before_body",
    "require",
    "require_owner",
]

SESSION_COOKIE = "mocapqa_session"
"""The browser's session cookie (HttpOnly)."""
CSRF_COOKIE = "mocapqa_csrf"
"""The session's CSRF token, readable by the page's script."""
CSRF_HEADER = "X-CSRF-Token"
"""The header a cookie-authenticated state-changing request repeats the CSRF token in."""
_STATE_CHANGING = frozenset({"POST", "PUT", "PATCH", "DELETE"})


@dataclass(frozen=True, slots=True)
class Principal:
    """Who a request acts as: a user (``user``), or the anonymous admin of a server with no
    users (``user`` None); ``via`` is ``token``, ``session`` or ``open``."""

    user: User | None
    role: Role
    via: str

    @property
    def name(self) -> str:
        """The user's name (``anonymous`` on an open server)."""
        return self.user.name if self.user else "anonymous"

    @property
    def user_id(self) -> int | None:
        """The user's id (None on an open server)."""
        return self.user.id if self.user else None


def get_accounts(connection: HTTPConnection) -> Accounts:
    """The app's account store."""
    return app_state(connection, "accounts", Accounts)


AccountsDep = Annotated[Accounts, Depends(get_accounts)]
"""Route parameter type that receives the app's :class:`Accounts`."""


def client_address(connection: HTTPConnection) -> str:
    """The client's address (for the audit log)."""
    return connection.client.host if connection.client else "unknown"


def _credential(connection: HTTPConnection) -> tuple[str, str] | None:
    """The credential a request presents: ``("api", token)`` from ``Authorization`` (token
    ``""`` when the header has another form), ``("session", cookie)``, or None."""
    header = connection.headers.get("authorization", "")
    if header:
        scheme, _, token = header.partition(" ")
        return ("api", token.strip() if scheme.lower() == "bearer" else "")
    cookie = connection.cookies.get(SESSION_COOKIE)
    return ("session", cookie) if cookie else None


def quota_key(user_id: int | None, address: str) -> str:
    """Whose quotas (queued runs, upload rate) and fair-queue line a request uses: the
    signed-in user's, else (anonymous) the client address's."""
    return f"user:{user_id}" if user_id is not None else address


def quota_key_before_body(connection: HTTPConnection, accounts: Accounts) -> str | None:
    """An upload's :func:`quota_key` from the credential alone, before the body is read, or
    None when :func:`get_principal` would refuse the request (401): a credential that is not
    valid, or none while users exist. A token or session is looked up by a hash and one query
    by primary key, with no write (``last_used_at`` is the route's to set).

    Raises
    ------
    ForbiddenError
        The credential's user has a role that may not upload (403, as :func:`require` would
        answer after the body).
    """
    credential = _credential(connection)
    if credential is None:
        return None if accounts.has_users() else client_address(connection)
    kind, token = credential
    holder = accounts.holder_of(token, kind) if token else None
    if holder is None:
        return None
    user_id, role = holder
    if not allows(role, Action.UPLOAD):
        raise ForbiddenError(
            f"Expected a role allowed to upload, got {role.value} (refused before the body)"
        )
    return quota_key(user_id, client_address(connection))


def get_principal(connection: HTTPConnection, accounts: AccountsDep) -> Principal:
    """Who the request acts as (see the module notes).

    Raises
    ------
    AuthenticationError
        Bad credentials, or none while users exist (401).
    ForbiddenError
        A cookie-authenticated state-changing request without the session's CSRF token (403).
    """
    credential = _credential(connection)
    if credential == ("api", ""):
        raise AuthenticationError("Expected 'Authorization: Bearer TOKEN', got another form")
    if credential is not None and credential[0] == "api":
        user, _ = accounts.verify(credential[1], "api")
        return Principal(user, user.role, "token")
    if credential is not None:
        user, csrf = accounts.verify(credential[1], "session")
        method = connection.scope.get("method", "GET")
        if method in _STATE_CHANGING:
            sent = connection.headers.get(CSRF_HEADER, "")
            if not csrf or not sent or sent != csrf:
                raise ForbiddenError(
                    f"Expected the session's CSRF token in the {CSRF_HEADER} header of a "
                    f"{method} request signed in with the cookie, got "
                    + ("a wrong one" if sent else "none")
                )
        return Principal(user, user.role, "session")
    if accounts.has_users():
        raise AuthenticationError(
            "Expected a signed-in user (session cookie or 'Authorization: Bearer TOKEN'), "
            "got neither"
        )
    return Principal(None, Role.ADMIN, "open")


PrincipalDep = Annotated[Principal, Depends(get_principal)]
"""Route parameter type that receives the request's :class:`Principal`."""


def require(action: Action) -> Callable[[Principal], Principal]:
    """A dependency refusing (403) a principal whose role may not perform ``action``."""

    def check(principal: PrincipalDep) -> Principal:
        if not allows(principal.role, action):
            raise ForbiddenError(
                f"Expected a role allowed to {action.value.replace('_', ' ')}, got "
                f"{principal.name!r} as {principal.role.value}"
            )
        return principal

    check.__name__ = f"require_{action.value}"
    return check


def require_owner(principal: Principal, owner_id: int | None, what: str) -> None:
    """Refuse (403) deleting or changing ``what`` unless the principal owns it or may delete
    anything: the one owner rule, which every owned resource's delete (and rename) route calls
    (takes, shoots). A resource without an owner (made before owners, or on a server without
    users) is an admin's alone.
    """
    if allows(principal.role, Action.DELETE_ANY):
        return
    if owner_id is None or owner_id != principal.user_id:
        raise ForbiddenError(
            f"Expected the owner of {what} or an admin, got {principal.name!r} "
            f"as {principal.role.value}"
        )


def audit(
    request: Request, principal: Principal, action: str, target: str, detail: str = ""
) -> None:
    """Record what a principal did, from the request's address."""
    get_accounts(request).record(action, principal.user, client_address(request), target, detail)
