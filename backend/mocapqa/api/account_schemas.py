"""Request and response models of the account routes (sign-in, users, tokens, audit)."""

from __future__ import annotations

from datetime import datetime

from pydantic import BaseModel, Field, StrictBool

from mocapqa.api.request_model import RequestModel
from mocapqa.store.roles import Action, Role

__all__ = [
    "USER_NAME",
    "AuditOut",
    "AuditPageOut",
    "MeOut",
    "SignInIn",
    "TokenCreatedOut",
    "TokenIn",
    "TokenOut",
    "UserIn",
    "UserOut",
    "UserPatchIn",
]


class SignInIn(RequestModel):
    """A browser sign-in."""

    name: str = Field(min_length=1, max_length=64)
    password: str = Field(min_length=1, max_length=1024)


class MeOut(BaseModel):
    """Who the caller is and what they may do (the UI shows only those controls)."""

    name: str
    user_id: int | None
    role: Role
    via: str = Field(description="token, session, or open (a server without users)")
    can: list[Action]


class UserOut(BaseModel):
    """A user (never the password hash)."""

    id: int
    name: str
    role: Role
    disabled: bool
    has_password: bool
    created_at: datetime


USER_NAME = r"^[A-Za-z0-9][A-Za-z0-9._@-]{0,63}$"
"""What a user name may hold (the store checks the same)."""


class UserIn(RequestModel):
    """A new user; without a password it signs in only with tokens."""

    name: str = Field(pattern=USER_NAME)
    role: Role
    password: str | None = Field(None, min_length=8, max_length=1024)


class UserPatchIn(RequestModel):
    """Changes to a user."""

    role: Role | None = None
    disabled: StrictBool | None = None
    password: str | None = Field(None, min_length=8, max_length=1024)


class TokenIn(RequestModel):
    """A new personal token."""

    name: str = Field("", max_length=255)
    expires_days: int = Field(90, ge=1, le=3650)


class TokenOut(BaseModel):
    """A personal token (its secret is shown only once, when made)."""

    id: str
    name: str
    user: str
    created_at: datetime
    expires_at: datetime
    last_used_at: datetime | None
    revoked_at: datetime | None


class TokenCreatedOut(BaseModel):
    """A token just made: ``token`` is shown this once and never again."""

    id: str
    token: str
    expires_at: datetime


class AuditOut(BaseModel):
    """One audit entry."""

    id: int
    at: datetime
    user_id: int | None
    user_name: str | None
    action: str
    target: str
    detail: str
    client: str


class AuditPageOut(BaseModel):
    """A page of the audit log, newest first."""

    items: list[AuditOut]
    total: int
    limit: int
    offset: int
