"""Options shared by the commands that read a BVH: ``--mapping FILE`` (with its warning about
roles not found) and ``--root-translation``.

Every such command takes ``--mapping`` (a JSON or TOML file of role → joint name, see
:mod:`mocapqa.io.mapping`) and, for a BVH take, prints one warning line on stderr naming the
roles that were found neither by name nor in the mapping, so a check that skips a limb never
does so silently.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import typer

from mocapqa.cli.app import err_console

if TYPE_CHECKING:
    from mocapqa.core.motion import Skeleton

__all__ = [
    "FpsOption",
    "MappingOption",
    "RootTranslationOption",
    "load_mapping",
    "missing_roles",
    "warn_missing",
]

MappingOption = Annotated[
    Path | None,
    typer.Option(
        "--mapping",
        help='Rig roles by hand: JSON or TOML, role → joint, e.g. {"left_upper_arm": "LeftArm"}.',
    ),
]
"""The ``--mapping FILE`` option."""

FpsOption = Annotated[
    float | None,
    typer.Option(
        help="Frames per second, for formats that do not store it (OpenPose, NPY, CSV, ...)."
    ),
]
"""The ``--fps`` option of the commands that read a take."""

RootTranslationOption = Annotated[
    Literal["auto", "add", "replace"],
    typer.Option(
        "--root-translation",
        help="BVH root position: add the channels to the root OFFSET, replace it (the BVH "
        "convention, as Blender reads it), or auto-detect (default).",
    ),
]
"""The ``--root-translation auto|add|replace`` option of the commands that place joints."""


def load_mapping(path: Path | None) -> dict[str, str] | None:
    """The mapping file's role key → joint name, or None without ``--mapping``."""
    if path is None:
        return None
    from mocapqa.io.mapping import read_mapping

    return read_mapping(path)


def missing_roles(
    skeleton: Skeleton, mapping: dict[str, str] | None, *, warn: bool = True
) -> list[str]:
    """Role keys found neither by name nor in ``mapping``; printed as a warning on stderr.

    Raises
    ------
    InputError
        If the mapping names a joint the skeleton does not have.
    """
    from mocapqa.core.rig import find_roles

    missing = list(find_roles(skeleton, mapping).unmapped)
    if warn:
        warn_missing(missing)
    return missing


def warn_missing(missing: list[str]) -> None:
    """Print the one warning line about roles not found (nothing when none is missing)."""
    if missing:
        err_console.print(
            f"[yellow]warning:[/] rig roles not found: {', '.join(missing)}; the checks of "
            "those limbs are skipped (name the joints with --mapping FILE, see docs/rigs.md)"
        )
