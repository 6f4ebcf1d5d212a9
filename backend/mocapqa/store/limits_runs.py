"""Takes of a shoot whose latest run checked joint limits with another model than the shoot's.

A run records the limits model it used in its options (``limits_model``, set when the run is
recorded: :meth:`mocapqa.store.repository.Repository.add_run`). When an admin chooses another
model for a shoot, the runs already made keep theirs; these queries find the motion takes whose
latest run (the one the shoot's table shows) used another model, so that the shoot's summary
can count them and an admin can run them again. Keypoint takes are not counted: they have no
joint limits. Runs recorded before models could be chosen (no ``limits_model``) used the
default choice.
"""

from __future__ import annotations

from typing import Any

from sqlalchemy import Engine, Select, func, select

from mocapqa.store.tables import runs, shoots, take_qa

__all__ = ["stale_limits_counts", "stale_limits_runs"]


def _stale(shoot_id: str | None) -> Select[Any]:
    """The latest runs of motion takes whose limits model is not their shoot's."""
    from mocapqa.limits.catalog import DEFAULT_MODEL

    used = func.coalesce(runs.c.options["limits_model"].as_string(), DEFAULT_MODEL)
    query = (
        select(take_qa.c.shoot_id, take_qa.c.take_id, runs.c.options)
        .join(runs, runs.c.id == take_qa.c.run_id)
        .join(shoots, shoots.c.id == take_qa.c.shoot_id)
        .where(take_qa.c.kind == "motion", used != shoots.c.limits_model)
    )
    return query if shoot_id is None else query.where(take_qa.c.shoot_id == shoot_id)


def stale_limits_counts(engine: Engine, shoot_id: str | None = None) -> dict[str, int]:
    """Shoot id → motion takes whose latest run used another limits model than the shoot's
    (shoots with none are absent); one shoot's, or every shoot's when ``shoot_id`` is None."""
    stale = _stale(shoot_id).subquery()
    query = select(stale.c.shoot_id, func.count().label("n")).group_by(stale.c.shoot_id)
    with engine.connect() as conn:
        return {str(row.shoot_id): int(row.n) for row in conn.execute(query)}


def stale_limits_runs(engine: Engine, shoot_id: str) -> list[tuple[str, dict[str, Any]]]:
    """``(take id, options of its latest run)`` of each motion take of the shoot whose latest
    run used another limits model than the shoot's, oldest take first."""
    query = _stale(shoot_id).order_by(take_qa.c.created_at, take_qa.c.take_id)
    with engine.connect() as conn:
        return [(str(row.take_id), dict(row.options)) for row in conn.execute(query)]
