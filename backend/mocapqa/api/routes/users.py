"""Users (admins), personal tokens (everyone's own; admins all) and the audit log (admins,
read only: no route changes it)."""

from __future__ import annotations

from datetime import timedelta
from typing import Annotated

from fastapi import APIRouter, Depends, Query, Request, Response

from mocapqa.api.account_schemas import (
    AuditOut,
    AuditPageOut,
    TokenCreatedOut,
    TokenIn,
    TokenOut,
    UserIn,
    UserOut,
    UserPatchIn,
)
from mocapqa.api.auth import AccountsDep, Principal, audit, require
from mocapqa.api.errors import responses
from mocapqa.errors import ForbiddenError
from mocapqa.store.roles import Action, allows

__all__ = ["router"]

router = APIRouter(tags=["accounts"])
"""Routes of this resource, included under ``/api/v1``."""
Admin = Annotated[Principal, Depends(require(Action.MANAGE_USERS))]
Anyone = Annotated[Principal, Depends(require(Action.OWN_TOKENS))]
Auditor = Annotated[Principal, Depends(require(Action.READ_AUDIT))]
_USER_ERRORS = responses(401, 403, 404, 409, 413)


@router.get("/users", responses=responses(401, 403))
def list_users(principal: Admin, accounts: AccountsDep) -> list[UserOut]:
    """Every user (admins)."""
    del principal
    return [UserOut.model_validate(u, from_attributes=True) for u in accounts.list_users()]


@router.post("/users", status_code=201, responses=_USER_ERRORS)
def add_user(body: UserIn, request: Request, principal: Admin, accounts: AccountsDep) -> UserOut:
    """Create a user (admins); without a password it signs in only with tokens."""
    user = accounts.add_user(body.name, body.role, body.password)
    audit(request, principal, "user_add", user.name, f"role={user.role.value}")
    return UserOut.model_validate(user, from_attributes=True)


@router.patch("/users/{name}", responses=_USER_ERRORS)
def change_user(
    name: str, body: UserPatchIn, request: Request, principal: Admin, accounts: AccountsDep
) -> UserOut:
    """Change a user's role, disabled flag or password (admins). Disabling a user revokes
    their tokens and sessions; the last enabled admin cannot be demoted or disabled (409)."""
    user = accounts.update_user(name, body.role, body.disabled, body.password)
    changes = [f"role={body.role.value}"] if body.role else []
    if body.disabled is not None:
        changes.append(f"disabled={body.disabled}")
    if body.password is not None:
        changes.append("password changed")
    audit(request, principal, "user_change", user.name, ", ".join(changes))
    return UserOut.model_validate(user, from_attributes=True)


@router.get("/tokens", responses=responses(401, 403))
def list_tokens(principal: Anyone, accounts: AccountsDep, everyone: bool = False) -> list[TokenOut]:
    """The caller's personal tokens; with ``everyone=true``, every user's (admins; 403 for
    anyone else, rather than their own list under a request for everyone's)."""
    if everyone:
        if not allows(principal.role, Action.MANAGE_USERS):
            raise ForbiddenError(
                f"Expected an admin to list every user's tokens, got a {principal.role.value}"
            )
        return [TokenOut.model_validate(t) for t in accounts.list_tokens()]
    if principal.user is None:
        return []
    return [TokenOut.model_validate(t) for t in accounts.list_tokens(principal.user.id)]


@router.post("/tokens", status_code=201, responses=responses(401, 403, 409, 413))
def create_token(
    body: TokenIn, request: Request, principal: Anyone, accounts: AccountsDep
) -> TokenCreatedOut:
    """A new personal token for the caller, shown this once (stored hashed)."""
    if principal.user is None:
        raise ForbiddenError(
            "Expected a signed-in user to own the token, got a server without users "
            "(create one with `mocapqa users add`)"
        )
    issued = accounts.issue(principal.user.id, "api", timedelta(days=body.expires_days), body.name)
    audit(request, principal, "token_create", issued.id, f"expires {issued.expires_at:%Y-%m-%d}")
    return TokenCreatedOut(id=issued.id, token=issued.token, expires_at=issued.expires_at)


@router.delete("/tokens/{token_id}", status_code=204, responses=responses(401, 403, 404, 413))
def revoke_token(
    token_id: str, request: Request, principal: Anyone, accounts: AccountsDep
) -> Response:
    """Revoke a personal token: the caller's own, or anyone's (admins)."""
    owner = accounts.token_owner(token_id)
    if owner != principal.user_id and not allows(principal.role, Action.MANAGE_USERS):
        raise ForbiddenError(
            f"Expected your own token or an admin, got token {token_id} of another user"
        )
    accounts.revoke(token_id)
    audit(request, principal, "token_revoke", token_id)
    return Response(status_code=204)


@router.get("/audit", responses=responses(401, 403))
def list_audit(
    principal: Auditor,
    accounts: AccountsDep,
    limit: Annotated[int, Query(ge=1, le=500)] = 100,
    offset: Annotated[int, Query(ge=0, le=2**31 - 1)] = 0,
) -> AuditPageOut:
    """A page of the audit log, newest first (admins; there is no route that changes it)."""
    del principal
    rows, total = accounts.list_audit(limit, offset)
    return AuditPageOut(
        items=[AuditOut.model_validate(r) for r in rows], total=total, limit=limit, offset=offset
    )
