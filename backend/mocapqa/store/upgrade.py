"""Bring a database made by an earlier version up to the current schema, in place.

Until the project adopts migrations, changes are additive and applied here when the repository
opens a database: ``metadata.create_all`` adds new tables (``shoots``, ``take_qa``); this module
adds the nullable ``takes.shoot_id`` column (and its index) that ``create_all`` cannot add to an
existing table, and fills ``take_qa`` for takes that have no row yet.
"""

from __future__ import annotations

from sqlalchemy import Engine, inspect, select, text

from mocapqa.store.qa import sync_take
from mocapqa.store.tables import take_qa, takes

__all__ = ["upgrade_schema"]


def upgrade_schema(engine: Engine) -> list[str]:
    """Apply the additive changes a database lacks; returns what was done (for the log)."""
    done: list[str] = []
    columns = {c["name"] for c in inspect(engine).get_columns("takes")}
    with engine.begin() as conn:
        if "shoot_id" not in columns:
            conn.execute(
                text("ALTER TABLE takes ADD COLUMN shoot_id VARCHAR(32) REFERENCES shoots (id)")
            )
            conn.execute(text("CREATE INDEX IF NOT EXISTS ix_takes_shoot_id ON takes (shoot_id)"))
            done.append("added takes.shoot_id")
        missing = [
            str(take_id)
            for take_id in conn.execute(
                select(takes.c.id).where(~takes.c.id.in_(select(take_qa.c.take_id)))
            ).scalars()
        ]
        for take_id in missing:
            sync_take(conn, take_id)
        if missing:
            done.append(f"filled take_qa for {len(missing)} take(s)")
    return done
