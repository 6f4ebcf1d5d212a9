"""Entry point of the ``mocapqa`` command: registers the command modules and maps errors."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence

from rich.markup import escape

from mocapqa.cli.app import app, err_console, exit_code_for
from mocapqa.errors import InputError, MocapQAError

__all__ = ["COMMAND_MODULES", "import_command_module", "main", "modules_for"]

COMMAND_MODULES: dict[str, tuple[str, ...]] = {
    "info": ("info",),
    "convert": ("info",),
    "detect": ("twist",),
    "refine": ("twist",),
    "filter": ("filters",),
    "render": ("render",),
    "report": ("report",),
    "serve": ("serve",),
    "batch": ("batch",),
    "users": ("accounts",),
    "tokens": ("accounts",),
    "db": ("database",),
    "limits": ("limits",),
    "feet": ("feet",),
    "markers": ("markers",),
    "bench api": ("bench_api",),
    "bench batch": ("bench_batch",),
    "bench feet": ("bench_feet",),
    "bench io": ("bench_io",),
    "bench filters": ("bench_filters",),
    "bench limits": ("bench_limits",),
    "bench markers": ("bench_markers",),
    "bench render": ("bench_render",),
    "bench twist": ("bench_twist",),
}
"""The modules that register each command (a test checks the table): those of
:mod:`mocapqa.cli`, and for ``bench …`` (``bench_*``) those of :mod:`mocapqa_bench.cli`."""
_ALL_MODULES = tuple(sorted({m for modules in COMMAND_MODULES.values() for m in modules}))


def modules_for(argv: Sequence[str]) -> tuple[str, ...]:
    """The command modules to import for a command line: those of its command, or all.

    Only the invoked command's module is imported (each costs a few ms to register, and
    ``mocapqa info`` should start fast); help, no command, or an unknown one load them all, so
    that Typer lists every command or suggests the nearest.
    """
    words = [arg for arg in argv if not arg.startswith("-")]
    key = " ".join(words[:2] if words[:1] == ["bench"] else words[:1])
    return COMMAND_MODULES.get(key, _ALL_MODULES)


def import_command_module(module: str) -> None:
    """Import a module of :data:`COMMAND_MODULES`, registering its commands.

    The ``bench_*`` modules are the benchmarks' (:mod:`mocapqa_bench.cli`): this is the one
    place the product imports the benchmarks (an import contract checks it).
    """
    if module.startswith("bench_"):
        from mocapqa_bench.cli import load

        load(module)
    else:
        importlib.import_module(f"mocapqa.cli.{module}")


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; user errors print one line and exit non-zero, without a traceback.

    Typer runs in its standalone mode: it prints usage errors itself and ends every run with
    ``SystemExit``, whose code is returned here, so no exception class of its bundled Click
    is needed.
    """
    args = sys.argv[1:] if argv is None else argv
    for module in modules_for(args):
        import_command_module(module)
    try:
        app(args=args, prog_name="mocapqa")
    except SystemExit as e:
        code = e.code
        return code if isinstance(code, int) else (0 if code is None else 1)
    except MocapQAError as e:
        return _report(e)
    except OSError as e:
        # Readers turn their OSErrors into ParseErrors, so this is an output that cannot be
        # written (a missing folder, no permission, a full disk, ``ulimit -f``). Writers go
        # through mocapqa.io.atomic, which names the output (not its temporary) as filename.
        path = str(e.filename) if e.filename else "an output file"
        got = e.strerror or type(e).__name__
        return _report(InputError(f"Expected a writable output path, got {got}: {path}"))
    return 0


def _report(error: MocapQAError) -> int:
    """Print one line, never wrapped and not read as Rich markup; return the exit code."""
    err_console.print(f"[bold red]error:[/] {escape(str(error))}", soft_wrap=True)
    return exit_code_for(error)


if __name__ == "__main__":
    sys.exit(main())


def _entry() -> None:
    sys.exit(main())
