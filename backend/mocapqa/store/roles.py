"""The one definition of roles and of what each may do, for the API, the CLI and the UI.

A role allows what the roles below it allow and more: **viewer** reads; **reviewer** also
uploads, runs analyses, reviews and deletes the takes (and shoots) it owns; **admin** also
deletes anything, manages users and everyone's tokens, reads the audit log and chooses a
shoot's joint-limits model. Each API route
names the :class:`Action` it performs (``api/auth.py``'s ``require``); ``GET /api/v1/me``
lists the actions the caller may perform, and the UI shows only those controls.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["NEEDS", "Action", "Role", "allowed_actions", "allows"]


class Role(StrEnum):
    """A user's role, lowest first."""

    VIEWER = "viewer"
    REVIEWER = "reviewer"
    ADMIN = "admin"

    @property
    def rank(self) -> int:
        """0 for viewer, 1 for reviewer, 2 for admin."""
        return list(Role).index(self)


class Action(StrEnum):
    """What a request does, as far as permissions go."""

    READ = "read"
    UPLOAD = "upload"
    RUN = "run"
    REVIEW = "review"
    DELETE_OWN = "delete_own"
    DELETE_ANY = "delete_any"
    OWN_TOKENS = "own_tokens"
    MANAGE_USERS = "manage_users"
    READ_AUDIT = "read_audit"
    CHOOSE_LIMITS_MODEL = "choose_limits_model"


NEEDS: dict[Action, Role] = {
    Action.READ: Role.VIEWER,
    Action.OWN_TOKENS: Role.VIEWER,
    Action.UPLOAD: Role.REVIEWER,
    Action.RUN: Role.REVIEWER,
    Action.REVIEW: Role.REVIEWER,
    Action.DELETE_OWN: Role.REVIEWER,
    Action.DELETE_ANY: Role.ADMIN,
    Action.MANAGE_USERS: Role.ADMIN,
    Action.READ_AUDIT: Role.ADMIN,
    Action.CHOOSE_LIMITS_MODEL: Role.ADMIN,
}
"""The lowest role allowed each action."""


def allows(role: Role, action: Action) -> bool:
    """Whether ``role`` may perform ``action``."""
    return role.rank >= NEEDS[action].rank


def allowed_actions(role: Role) -> list[str]:
    """The actions ``role`` may perform, by name."""
    return [action.value for action in Action if allows(role, action)]
