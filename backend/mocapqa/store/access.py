"""The base of the store's table classes: they read and write on the repository's engine."""

from __future__ import annotations

from sqlalchemy import Engine

__all__ = ["TableAccess"]


class TableAccess:
    """Reads and writes of some of the store's tables.

    Parameters
    ----------
    engine : Engine
        The repository's engine (its schema already created).
    """

    def __init__(self, engine: Engine) -> None:
        self.engine = engine
