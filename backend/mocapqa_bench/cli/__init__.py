"""The ``mocapqa bench …`` commands: each module registers its command on
:data:`mocapqa.cli.app.bench_app` when imported (:func:`load`)."""

from __future__ import annotations

import importlib

__all__ = ["load"]


def load(module: str) -> None:
    """Import the command module ``module`` of this package (``"bench_twist"``, ...), which
    registers its command on the ``mocapqa bench`` group."""
    importlib.import_module(f"{__name__}.{module}")
