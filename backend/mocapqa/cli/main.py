"""Entry point of the ``mocapqa`` command: registers every command module and maps errors."""

from __future__ import annotations

import sys

from rich.markup import escape

from mocapqa.cli import (
    bench_io,  # noqa: F401  (registers commands)
    info,  # noqa: F401  (registers commands)
    limits,  # noqa: F401  (registers commands)
    render,  # noqa: F401  (registers commands)
    report,  # noqa: F401  (registers commands)
    serve,  # noqa: F401  (registers commands)
)
from mocapqa.cli import filters as filter_commands  # noqa: F401  (registers commands)
from mocapqa.cli import twist as twist_commands  # noqa: F401  (registers commands)
from mocapqa.cli.app import app, err_console, exit_code_for
from mocapqa.errors import MocapQAError

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; user errors print one line and exit non-zero, without a traceback.

    Typer runs in its standalone mode: it prints usage errors itself and ends every run with
    ``SystemExit``, whose code is returned here, so no exception class of its bundled Click
    is needed.
    """
    try:
        app(args=argv, prog_name="mocapqa")
    except SystemExit as e:
        code = e.code
        return code if isinstance(code, int) else (0 if code is None else 1)
    except MocapQAError as e:
        # One line, never wrapped, and the message is not read as Rich markup.
        err_console.print(f"[bold red]error:[/] {escape(str(e))}", soft_wrap=True)
        return exit_code_for(e)
    return 0


if __name__ == "__main__":
    sys.exit(main())


def _entry() -> None:
    sys.exit(main())
