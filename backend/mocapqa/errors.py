"""The one exception hierarchy of mocapqa.

Every error a user can cause is a :class:`MocapQAError`. The HTTP status codes and the CLI exit
codes for these classes live in one table each (``api/errors.py`` and ``cli.py``); this module
knows nothing of either. Messages read "Expected X, got Y" plus where the problem is.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "AuthenticationError",
    "ClusterError",
    "ConflictError",
    "ForbiddenError",
    "FormatError",
    "InputError",
    "LimitsFileError",
    "MocapQAError",
    "NotFoundError",
    "OptionError",
    "ParseError",
    "RateLimitError",
    "RenderUnavailableError",
    "ShapeError",
    "TooLargeError",
    "UnsupportedFormatError",
]


class MocapQAError(Exception):
    """Root of every error mocapqa raises on purpose."""


class InputError(MocapQAError):
    """The input (a file, an array, an option) is not what was expected."""


class ParseError(InputError):
    """A file could not be parsed.

    Parameters
    ----------
    message : str
        What was expected and what was found.
    path : str or Path, optional
        The file being read.
    line : int, optional
        1-based line number of the problem.
    field : str, optional
        The field or column name, for tabular and JSON inputs.
    """

    def __init__(
        self,
        message: str,
        path: str | Path | None = None,
        line: int | None = None,
        field: str | None = None,
    ) -> None:
        self.message = message
        self.path = str(path) if path is not None else None
        self.line = line
        self.field = field
        where = []
        if self.path is not None:
            where.append(self.path)
        if line is not None:
            where.append(f"line {line}")
        if field is not None:
            where.append(f"field {field!r}")
        prefix = ", ".join(where)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class OptionError(InputError):
    """A run option is invalid, or does not suit the take.

    Parameters
    ----------
    field : str
        The option's name (dotted for a filter parameter, e.g. ``filter_params.beta``).
    message : str
        What was expected and what was found.
    """

    def __init__(self, field: str, message: str) -> None:
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")


class FormatError(InputError):
    """A file's format could not be recognised or is not supported for this operation."""


class UnsupportedFormatError(FormatError):
    """The file's format is known but not readable or writable here."""


class ShapeError(InputError):
    """An array does not have the expected shape or dtype."""


class LimitsFileError(InputError):
    """A joint-limits model file is corrupt, or was built for another rig."""


class TooLargeError(InputError):
    """An input exceeds a configured size limit."""


class NotFoundError(MocapQAError):
    """A take, run or other stored object does not exist."""


class ConflictError(MocapQAError):
    """The request conflicts with the stored state (for example a run that is not finished)."""


class ForbiddenError(MocapQAError):
    """The request is not allowed: from where it came (a cross-site upload, a missing CSRF
    token) or for who sent it (a role that may not do this, a take owned by another user)."""


class AuthenticationError(MocapQAError):
    """The request names no valid user: no credentials while the server has users, an unknown,
    expired or revoked token, a wrong password, or a disabled user."""


class RateLimitError(MocapQAError):
    """A client asked for more than its share (queued runs, uploads per minute).

    Parameters
    ----------
    message : str
        What was exceeded.
    retry_after_s : int
        Seconds after which the request may succeed.
    """

    def __init__(self, message: str, retry_after_s: int) -> None:
        self.retry_after_s = max(1, int(retry_after_s))
        super().__init__(message)


class ClusterError(MocapQAError):
    """The Dask scheduler cannot be reached, or the connection to it was lost while working."""


class RenderUnavailableError(MocapQAError):
    """Off-screen rendering is not available on this machine."""
