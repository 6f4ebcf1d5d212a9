"""The Typer application objects and the one table mapping errors to exit codes.

Command modules (``info``, ``twist``, ``limits``, ...) register on these apps; ``main`` imports
them all. Heavy libraries are imported inside commands so that ``mocapqa info`` starts fast.
"""

from __future__ import annotations

import typer
from rich.console import Console

from mocapqa.errors import (
    ClusterError,
    ConflictError,
    InputError,
    LimitsFileError,
    MocapQAError,
    NotFoundError,
    RenderUnavailableError,
)

__all__ = ["EXIT_CODES", "app", "bench_app", "err_console", "exit_code_for", "limits_app"]

app = typer.Typer(
    name="mocapqa",
    help="Motion-capture QA: find and fix twist errors, joint-limit violations and noise.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)
"""The ``mocapqa`` command; command modules register on it."""
bench_app = typer.Typer(help="Benchmarks that print tables of figures.", no_args_is_help=True)
"""The ``mocapqa bench`` group."""
limits_app = typer.Typer(help="Build, check and show joint-limit models.", no_args_is_help=True)
"""The ``mocapqa limits`` group."""
app.add_typer(bench_app, name="bench")
app.add_typer(limits_app, name="limits")

err_console = Console(stderr=True, highlight=False)
"""Console on stderr for one-line error messages."""

# Most specific class first: the first match wins.
EXIT_CODES: tuple[tuple[type[MocapQAError], int], ...] = (
    (LimitsFileError, 6),
    (InputError, 3),
    (NotFoundError, 4),
    (ConflictError, 5),
    (RenderUnavailableError, 7),
    (ClusterError, 8),
    (MocapQAError, 1),
)


def exit_code_for(error: MocapQAError) -> int:
    """Exit code for an error, from :data:`EXIT_CODES`."""
    for cls, code in EXIT_CODES:
        if isinstance(error, cls):
            return code
    return 1
