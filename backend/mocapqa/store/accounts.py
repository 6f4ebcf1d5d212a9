"""Users, their credentials (personal tokens, browser sessions, one-time sign-in links) and
the audit log, on the same database as the takes.

A token is ``mqa_<id>_<secret>``: the id finds the row, the secret (256 random bits) is
compared by its SHA-256 in constant time. Passwords are hashed with argon2 (``pwdlib``).
Secrets are returned once, when made, and never stored.
"""

from __future__ import annotations

import hashlib
import hmac
import re
import secrets
from dataclasses import dataclass
from datetime import datetime, timedelta
from typing import Any

from pwdlib import PasswordHash
from sqlalchemy import Engine, func, insert, select, update

from mocapqa.errors import AuthenticationError, ConflictError, InputError, NotFoundError
from mocapqa.store.audit_log import AuditLog
from mocapqa.store.last_use import LastUse
from mocapqa.store.roles import Role
from mocapqa.store.rows import read_rows, utc
from mocapqa.store.stamps import new_id, utc_now
from mocapqa.store.tables import tokens, users

__all__ = [
    "LINK_TTL",
    "SESSION_TTL",
    "Accounts",
    "Issued",
    "User",
    "parse_role",
]

SESSION_TTL = timedelta(days=7)
"""How long a browser sign-in lasts."""
LINK_TTL = timedelta(minutes=15)
"""How long a one-time sign-in link stays usable."""
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._@-]{0,63}$")
_TOKEN = re.compile(r"^mqa_([0-9a-f]{32})_([A-Za-z0-9_-]{20,100})$")
_hasher = PasswordHash.recommended()  # argon2id with the library's recommended parameters


@dataclass(frozen=True, slots=True)
class User:
    """A user as the API and CLI see it."""

    id: int
    name: str
    role: Role
    disabled: bool
    has_password: bool
    created_at: datetime


@dataclass(frozen=True, slots=True)
class Issued:
    """A credential just made: its id, the secret to hand out once, when it expires."""

    id: str
    token: str
    expires_at: datetime
    csrf: str | None = None


def parse_role(value: str) -> Role:
    """A role from its name.

    Raises
    ------
    InputError
    """
    try:
        return Role(value)
    except ValueError:
        raise InputError(f"Expected role in {[r.value for r in Role]}, got {value!r}") from None


def _digest(secret: str) -> str:
    return hashlib.sha256(secret.encode()).hexdigest()


def _usable(row: Any, kind: str, secret: str, now: datetime | None = None) -> bool:
    """Whether a token row (joined with its user) is a live credential of ``kind`` for
    ``secret``."""
    return bool(
        row.kind == kind
        and hmac.compare_digest(row.secret_sha256, _digest(secret))
        and row.revoked_at is None
        and utc(row.expires_at) > (now or utc_now())
        and not row.disabled
    )


_USER_COLUMNS = (
    users.c.name.label("user_name"),
    users.c.role,
    users.c.disabled,
    users.c.password_hash,
    users.c.created_at.label("user_created_at"),
)
"""A user's columns beside a token's in one row (both tables have ``name`` and ``created_at``)."""


def _joined_user(row: Any) -> User:
    """The user of a token row joined with :data:`_USER_COLUMNS`."""
    return User(
        id=int(row.user_id),
        name=str(row.user_name),
        role=Role(row.role),
        disabled=bool(row.disabled),
        has_password=row.password_hash is not None,
        created_at=utc(row.user_created_at),
    )


def _user(row: Any) -> User:
    return User(
        id=int(row.id),
        name=str(row.name),
        role=Role(row.role),
        disabled=bool(row.disabled),
        has_password=row.password_hash is not None,
        created_at=utc(row.created_at),
    )


class Accounts(AuditLog):
    """Users, credentials and the audit log (:class:`~mocapqa.store.audit_log.AuditLog`) on a
    database engine (the repository's)."""

    def __init__(self, engine: Engine) -> None:
        super().__init__(engine)
        self.last_use = LastUse(engine)
        """Coalesced writes of credentials' ``last_used_at`` (:meth:`verify` notes)."""

    # users -----------------------------------------------------------------------------
    def has_users(self) -> bool:
        """Whether any user exists (the API asks for credentials only then)."""
        with self.engine.connect() as conn:
            return conn.execute(select(users.c.id).limit(1)).first() is not None

    def add_user(self, name: str, role: Role, password: str | None = None) -> User:
        """Create a user (``password`` None: token-only).

        Raises
        ------
        InputError
            A name that is not 1–64 letters, digits or ``._@-``.
        ConflictError
            The name is taken.
        """
        if not _NAME.match(name):
            raise InputError(
                f"Expected a user name of 1-64 letters, digits or ._@- (starting with a letter "
                f"or digit), got {name!r}"
            )
        with self.engine.begin() as conn:
            # Names differing only in case ("ADMIN", "admin") would read as one person in the
            # audit log and the review history: one of them is refused.
            taken = conn.execute(
                select(users.c.name).where(func.lower(users.c.name) == name.lower())
            ).first()
            if taken:
                raise ConflictError(
                    f"Expected a new user name, got {name!r}, which exists as {taken[0]!r}"
                )
            conn.execute(
                insert(users).values(
                    name=name,
                    role=role.value,
                    password_hash=_hasher.hash(password) if password else None,
                    disabled=False,
                    created_at=utc_now(),
                )
            )
        return self.get_user(name)

    def get_user(self, name: str) -> User:
        """A user by name.

        Raises
        ------
        NotFoundError
        """
        with self.engine.connect() as conn:
            row = conn.execute(select(users).where(users.c.name == name)).first()
        if row is None:
            raise NotFoundError(f"Expected user {name!r} to exist, got none")
        return _user(row)

    def user_by_id(self, user_id: int) -> User:
        """A user by id (:class:`NotFoundError` when missing)."""
        with self.engine.connect() as conn:
            row = conn.execute(select(users).where(users.c.id == user_id)).first()
        if row is None:
            raise NotFoundError(f"Expected user {user_id} to exist, got none")
        return _user(row)

    def list_users(self) -> list[User]:
        """Every user, by name."""
        with self.engine.connect() as conn:
            return [_user(r) for r in conn.execute(select(users).order_by(users.c.name))]

    def update_user(
        self,
        name: str,
        role: Role | None = None,
        disabled: bool | None = None,
        password: str | None = None,
    ) -> User:
        """Change a user's role, disabled flag or password. Disabling revokes every
        credential of the user.

        Raises
        ------
        NotFoundError
        ConflictError
            The change would leave no enabled admin.
        """
        user = self.get_user(name)
        values: dict[str, Any] = {}
        if role is not None:
            values["role"] = role.value
        if disabled is not None:
            values["disabled"] = disabled
        if password is not None:
            values["password_hash"] = _hasher.hash(password) if password else None
        # Only an enabled admin who stops being one (demoted or disabled) can leave no admin.
        demoting = (
            user.role is Role.ADMIN
            and not user.disabled
            and ((role is not None and role is not Role.ADMIN) or bool(disabled))
        )
        with self.engine.begin() as conn:
            if demoting:
                # Two admins demoting each other at once must not both succeed: PostgreSQL
                # locks the admin rows here (the second waits for the first to commit), SQLite
                # serialises the writes; the count below is taken after this change.
                conn.execute(
                    select(users.c.id).where(users.c.role == Role.ADMIN.value).with_for_update()
                )
            if values:
                conn.execute(update(users).where(users.c.id == user.id).values(**values))
            if demoting:
                admins = conn.execute(
                    select(func.count())
                    .select_from(users)
                    .where(users.c.role == Role.ADMIN.value, users.c.disabled.is_(False))
                ).scalar_one()
                if int(admins) < 1:
                    raise ConflictError(  # rolls the change back
                        f"Expected another enabled admin to remain, got {name!r} as the last one"
                    )
            if disabled:
                conn.execute(
                    update(tokens)
                    .where(tokens.c.user_id == user.id, tokens.c.revoked_at.is_(None))
                    .values(revoked_at=utc_now())
                )
        return self.get_user(name)

    def check_password(self, name: str, password: str) -> User:
        """The user, if the password is theirs and they are enabled.

        Raises
        ------
        AuthenticationError
            Unknown user, no password set, wrong password or disabled (one message for all).
        """
        with self.engine.connect() as conn:
            row = conn.execute(select(users).where(users.c.name == name)).first()
        stored = row.password_hash if row is not None else None
        # Hash even for an unknown user, so the answer takes as long either way.
        valid = _hasher.verify(password, stored) if stored else _hasher.hash(password) == ""
        if row is None or not valid or row.disabled:
            raise AuthenticationError("Expected a valid user name and password, got no match")
        return _user(row)

    # credentials -----------------------------------------------------------------------
    def issue(
        self, user_id: int, kind: str, ttl: timedelta, name: str = "", with_csrf: bool = False
    ) -> Issued:
        """Make a credential of ``kind`` (``api``, ``session`` or ``link``) for a user."""
        token_id = new_id()
        secret = secrets.token_urlsafe(32)
        csrf = secrets.token_urlsafe(32) if with_csrf else None
        now = utc_now()
        with self.engine.begin() as conn:
            conn.execute(
                insert(tokens).values(
                    id=token_id,
                    user_id=user_id,
                    kind=kind,
                    name=name[:255],
                    secret_sha256=_digest(secret),
                    csrf=csrf,
                    created_at=now,
                    expires_at=now + ttl,
                )
            )
        return Issued(token_id, f"mqa_{token_id}_{secret}", now + ttl, csrf)

    def verify(self, token: str, kind: str, consume: bool = False) -> tuple[User, str | None]:
        """The user a credential of ``kind`` names, and its CSRF token (sessions).

        A read: the use is noted for :class:`~mocapqa.store.last_use.LastUse` to record, at
        most once a minute per credential and off the request path. ``consume`` revokes the
        credential in the same step (one-time sign-in links), a write: of two requests
        presenting the same link, only one gets the user.

        Raises
        ------
        AuthenticationError
            Malformed, unknown, of another kind, expired, revoked, or of a disabled user.
        """
        match = _TOKEN.match(token)
        refused = AuthenticationError(f"Expected a valid {kind} token, got an unknown one")
        if match is None:
            raise refused
        token_id, secret = match.groups()
        now = utc_now()
        query = (
            select(tokens, *_USER_COLUMNS)
            .join(users, users.c.id == tokens.c.user_id)
            .where(tokens.c.id == token_id)
        )
        if not consume:
            with self.engine.connect() as conn:
                row = conn.execute(query).first()
            if row is None or not _usable(row, kind, secret, now):
                raise refused
            self.last_use.note(token_id, now)
            return _joined_user(row), row.csrf
        with self.engine.begin() as conn:
            row = conn.execute(query).first()
            if row is None or not _usable(row, kind, secret, now):
                raise refused
            used = conn.execute(
                update(tokens)
                .where(tokens.c.id == token_id, tokens.c.revoked_at.is_(None))
                .values(last_used_at=now, revoked_at=now)
            )
            if used.rowcount != 1:
                raise refused
        return _joined_user(row), row.csrf

    def user_id_of(self, token: str, kind: str) -> int | None:
        """The id of the user a valid credential of ``kind`` names, else None; reads only."""
        holder = self.holder_of(token, kind)
        return None if holder is None else holder[0]

    def holder_of(self, token: str, kind: str) -> tuple[int, Role] | None:
        """The id and role of the user a valid credential of ``kind`` names, else None;
        reads only.

        The cheap lookup for a quota and a role before a request's body is read (a hash and
        one query by primary key); :meth:`verify` is the full check a route makes.
        """
        match = _TOKEN.match(token)
        if match is None:
            return None
        token_id, secret = match.groups()
        with self.engine.connect() as conn:
            row = conn.execute(
                select(tokens, users.c.disabled, users.c.role)
                .join(users, users.c.id == tokens.c.user_id)
                .where(tokens.c.id == token_id)
            ).first()
        if row is None or not _usable(row, kind, secret):
            return None
        return int(row.user_id), Role(row.role)

    def list_tokens(self, user_id: int | None = None) -> list[dict[str, Any]]:
        """Personal tokens (never their secrets), newest first; of one user or of all."""
        query = (
            select(
                tokens.c.id,
                tokens.c.name,
                tokens.c.created_at,
                tokens.c.expires_at,
                tokens.c.last_used_at,
                tokens.c.revoked_at,
                users.c.name.label("user"),
            )
            .join(users, users.c.id == tokens.c.user_id)
            .where(tokens.c.kind == "api")
            .order_by(tokens.c.created_at.desc())
        )
        if user_id is not None:
            query = query.where(tokens.c.user_id == user_id)
        with self.engine.connect() as conn:
            return read_rows(conn, query)

    def token_owner(self, token_id: str) -> int:
        """The user id of a personal token (:class:`NotFoundError` when missing)."""
        with self.engine.connect() as conn:
            owner = conn.execute(
                select(tokens.c.user_id).where(tokens.c.id == token_id, tokens.c.kind == "api")
            ).scalar()
        if owner is None:
            raise NotFoundError(f"Expected token {token_id!r} to exist, got none")
        return int(owner)

    def revoke(self, token_id: str) -> None:
        """Revoke a credential (idempotent; :class:`NotFoundError` when unknown)."""
        with self.engine.begin() as conn:
            found = conn.execute(select(tokens.c.id).where(tokens.c.id == token_id)).first()
            if found is None:
                raise NotFoundError(f"Expected token {token_id!r} to exist, got none")
            conn.execute(
                update(tokens)
                .where(tokens.c.id == token_id, tokens.c.revoked_at.is_(None))
                .values(revoked_at=utc_now())
            )
