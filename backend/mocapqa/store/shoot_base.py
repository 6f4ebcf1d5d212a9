"""What the parts of the shoot store share: the engine, and the check that a shoot exists."""

from __future__ import annotations

from sqlalchemy import select

from mocapqa.errors import NotFoundError
from mocapqa.store.access import TableAccess
from mocapqa.store.tables import shoots

__all__ = ["ShootTables"]


class ShootTables(TableAccess):
    """The base of each part of :class:`~mocapqa.store.shoots.ShootStore`."""

    def require(self, shoot_id: str) -> None:
        """:class:`NotFoundError` unless the shoot exists (one indexed lookup, no counts)."""
        with self.engine.connect() as conn:
            found = conn.execute(select(shoots.c.id).where(shoots.c.id == shoot_id)).first()
        if found is None:
            raise NotFoundError(f"Expected shoot {shoot_id!r} to exist, got none")
