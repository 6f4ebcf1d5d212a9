"""Browser sign-in and sign-out, the one-time sign-in link, and ``GET /me``."""

from __future__ import annotations

from fastapi import APIRouter, Request, Response
from fastapi.responses import RedirectResponse

from mocapqa.api.account_schemas import MeOut, SignInIn
from mocapqa.api.auth import (
    CSRF_COOKIE,
    SESSION_COOKIE,
    AccountsDep,
    Principal,
    PrincipalDep,
    client_address,
)
from mocapqa.api.errors import responses
from mocapqa.api.http_guards import RateWindow
from mocapqa.errors import AuthenticationError, RateLimitError
from mocapqa.store.accounts import LINK_TTL, SESSION_TTL, Accounts, User
from mocapqa.store.roles import allowed_actions

__all__ = ["router", "sign_in_link"]

router = APIRouter(tags=["session"])
"""Routes of this resource, included under ``/api/v1``."""
LINK_PATH = "/api/v1/auth/link/"
"""Path of a one-time sign-in link; the token follows."""
SIGN_INS_PER_MINUTE = 10
"""Password sign-in attempts one address may make per minute (more get 429): enough for a
person's typos, too few to guess passwords."""


def _attempts(request: Request) -> RateWindow:
    """The app's window of sign-in attempts per address (made on first use)."""
    window = getattr(request.app.state, "sign_in_attempts", None)
    if not isinstance(window, RateWindow):
        window = RateWindow(SIGN_INS_PER_MINUTE)
        request.app.state.sign_in_attempts = window
    return window


def sign_in_link(accounts: Accounts, user: User, base_url: str) -> str:
    """A one-time sign-in link for a user (usable once, for :data:`LINK_TTL`)."""
    issued = accounts.issue(user.id, "link", LINK_TTL)
    return f"{base_url.rstrip('/')}{LINK_PATH}{issued.token}"


def _start_session(accounts: Accounts, user: User, request: Request, response: Response) -> None:
    issued = accounts.issue(user.id, "session", SESSION_TTL, with_csrf=True)
    secure = request.url.scheme == "https"
    max_age = int(SESSION_TTL.total_seconds())
    response.set_cookie(
        SESSION_COOKIE,
        issued.token,
        max_age=max_age,
        httponly=True,
        samesite="strict",
        secure=secure,
        path="/",
    )
    response.set_cookie(
        CSRF_COOKIE, issued.csrf or "", max_age=max_age, samesite="strict", secure=secure, path="/"
    )


def _me(principal: Principal) -> MeOut:
    return MeOut(
        name=principal.name,
        user_id=principal.user_id,
        role=principal.role,
        via=principal.via,
        can=allowed_actions(principal.role),  # type: ignore[arg-type]
    )


@router.post("/auth/sign-in", responses=responses(401, 403, 413, 429))
def sign_in(body: SignInIn, request: Request, response: Response, accounts: AccountsDep) -> MeOut:
    """Sign in with a name and password: sets the session cookie (HttpOnly, SameSite=Strict,
    Secure over https) and the CSRF cookie whose value state-changing requests repeat in
    ``X-CSRF-Token``. A failed attempt is recorded in the audit log; more than
    :data:`SIGN_INS_PER_MINUTE` attempts a minute from one address get 429."""
    address = client_address(request)
    wait = _attempts(request).admit(address)
    if wait > 0:
        accounts.record("sign_in_failed", None, address, body.name, "too many attempts")
        raise RateLimitError(
            f"Expected at most {SIGN_INS_PER_MINUTE} sign-in attempts a minute from one "
            "address, got more",
            retry_after_s=int(wait) + 1,
        )
    try:
        user = accounts.check_password(body.name, body.password)
    except AuthenticationError:
        accounts.record("sign_in_failed", None, address, body.name)
        raise
    _start_session(accounts, user, request, response)
    accounts.record("sign_in", user, address, user.name, "password")
    return _me(Principal(user, user.role, "session"))


@router.post("/auth/sign-out", status_code=204, responses=responses(401, 403, 413))
def sign_out(request: Request, principal: PrincipalDep, accounts: AccountsDep) -> Response:
    """End the browser's session (its cookie stops working) and clear the cookies."""
    response = Response(status_code=204)
    if principal.via == "session":
        token_id = request.cookies.get(SESSION_COOKIE, "")[4:36]
        accounts.revoke(token_id)
        accounts.record("sign_out", principal.user, client_address(request), principal.name)
    response.delete_cookie(SESSION_COOKIE, path="/")
    response.delete_cookie(CSRF_COOKIE, path="/")
    return response


@router.get("/auth/link/{token}", include_in_schema=False)
def use_link(token: str, request: Request, accounts: AccountsDep) -> Response:
    """A one-time sign-in link: starts a session and opens the dashboard; a used, expired or
    unknown link opens the sign-in page instead."""
    address = client_address(request)
    try:
        user, _ = accounts.verify(token, "link", consume=True)
    except AuthenticationError:
        accounts.record("sign_in_failed", None, address, "", "sign-in link refused")
        return RedirectResponse("/static/signin.html?link=refused", status_code=303)
    response = RedirectResponse("/", status_code=303)
    _start_session(accounts, user, request, response)
    accounts.record("sign_in", user, address, user.name, "one-time link")
    return response


@router.get("/me", responses=responses(401))
def me(principal: PrincipalDep) -> MeOut:
    """Who the caller is, their role, and the actions that role may perform."""
    return _me(principal)
