"""``mocapqa users add|list|set-role|disable`` and ``mocapqa tokens create|revoke``.

They act on the store named by ``MOCAPQA_DATA_DIR`` (or ``MOCAPQA_DATABASE_URL``), the same
one ``mocapqa serve`` uses, and record each change in its audit log (as done from the command
line, by no signed-in user). ``tokens create`` prints the new token as the last line of
stdout, so a script can take it with ``tail -n 1``.
"""

from __future__ import annotations

import getpass
import sys
from typing import TYPE_CHECKING, Annotated

import typer

from mocapqa.cli.app import app

if TYPE_CHECKING:
    from mocapqa.store.accounts import Accounts

__all__ = ["tokens_app", "users_app"]

users_app = typer.Typer(help="Manage users (roles: viewer, reviewer, admin).", no_args_is_help=True)
"""The ``mocapqa users`` group."""
tokens_app = typer.Typer(help="Create and revoke personal API tokens.", no_args_is_help=True)
"""The ``mocapqa tokens`` group."""
app.add_typer(users_app, name="users")
app.add_typer(tokens_app, name="tokens")

_CLI = "cli"
"""The audit log's client address for changes made on the command line."""
RoleOption = Annotated[
    str, typer.Option("--role", help="viewer (read), reviewer (+ upload, run, review), admin.")
]


def _accounts() -> Accounts:
    from mocapqa.config import get_settings
    from mocapqa.store.accounts import Accounts
    from mocapqa.store.repository import Repository

    settings = get_settings()
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    return Accounts(Repository(settings.resolved_database_url).engine)


def _password(from_stdin: bool, ask: bool) -> str | None:
    if from_stdin:
        return sys.stdin.readline().rstrip("\n") or None
    if ask:
        first = getpass.getpass("Password: ")
        if first != getpass.getpass("Again: "):
            raise typer.BadParameter("the two passwords differ")
        return first or None
    return None


@users_app.command("add")
def users_add(
    name: str,
    role: RoleOption = "reviewer",
    password_stdin: Annotated[
        bool, typer.Option("--password-stdin", help="Read the password from stdin's first line.")
    ] = False,
    password: Annotated[
        bool, typer.Option("--password", help="Ask for a password (none: token-only user).")
    ] = False,
) -> None:
    """Create a user; without a password it signs in only with tokens."""
    from mocapqa.store.accounts import parse_role

    accounts = _accounts()
    user = accounts.add_user(name, parse_role(role), _password(password_stdin, password))
    accounts.record("user_add", None, _CLI, user.name, f"role={user.role.value}")
    typer.echo(f"user {user.name} ({user.role.value}) created")


@users_app.command("list")
def users_list() -> None:
    """Every user: name, role, enabled, password or token-only."""
    for user in _accounts().list_users():
        state = "disabled" if user.disabled else "enabled"
        login = "password" if user.has_password else "tokens only"
        typer.echo(f"{user.name}\t{user.role.value}\t{state}\t{login}")


@users_app.command("set-role")
def users_set_role(
    name: str, role: Annotated[str, typer.Argument(help="viewer|reviewer|admin")]
) -> None:
    """Change a user's role."""
    from mocapqa.store.accounts import parse_role

    accounts = _accounts()
    user = accounts.update_user(name, role=parse_role(role))
    accounts.record("user_change", None, _CLI, user.name, f"role={user.role.value}")
    typer.echo(f"user {user.name} is now {user.role.value}")


@users_app.command("disable")
def users_disable(name: str) -> None:
    """Disable a user and revoke every token and session of theirs."""
    accounts = _accounts()
    user = accounts.update_user(name, disabled=True)
    accounts.record("user_change", None, _CLI, user.name, "disabled=True")
    typer.echo(f"user {user.name} disabled")


@tokens_app.command("create")
def tokens_create(
    user: Annotated[str, typer.Option("--user", help="The token's user.")],
    expires_days: Annotated[int, typer.Option("--expires-days", min=1, max=3650)] = 90,
    name: Annotated[str, typer.Option("--name", help="What the token is for.")] = "",
) -> None:
    """Create a personal token; it is printed once, as the last line of stdout.

    A disabled user gets none (exit 5, nothing printed on stdout): its tokens do not sign in.
    """
    from datetime import timedelta

    from mocapqa.errors import ConflictError

    accounts = _accounts()
    owner = accounts.get_user(user)
    if owner.disabled:
        raise ConflictError(
            f"Expected an enabled user to own the token, got {owner.name!r}, which is disabled "
            "(a disabled user's tokens do not sign in)"
        )
    issued = accounts.issue(owner.id, "api", timedelta(days=expires_days), name)
    accounts.record("token_create", None, _CLI, issued.id, f"user={owner.name}")
    typer.echo(f"token {issued.id} for {owner.name}, expires {issued.expires_at:%Y-%m-%d}")
    typer.echo(issued.token)


@tokens_app.command("revoke")
def tokens_revoke(token_id: Annotated[str, typer.Argument(help="The token's id.")]) -> None:
    """Revoke a token (it stops working at once)."""
    accounts = _accounts()
    accounts.revoke(token_id)
    accounts.record("token_revoke", None, _CLI, token_id)
    typer.echo(f"token {token_id} revoked")
