"""Takes of a shoot whose latest run checked joint limits with another model than the shoot's.

A run records the limits model it used in its options (``limits_model``, set when the run is
recorded: :func:`run_limits_model`). When an admin chooses another model for a shoot, the runs
already made keep theirs; these queries find the motion takes whose latest run (the one the
shoot's table shows) used another model, so that the shoot's summary can count them and an
admin can run them again. Keypoint takes are not counted: they have no joint limits. Runs
recorded before models could be chosen (no ``limits_model``) used the default choice.

A new run's model is chosen here too, for the server's runs and a batch's alike
(:func:`run_limits_model`): the one its options name, else its shoot's, else the catalog's
default.
"""

from __future__ import annotations

from typing import Any

from sqlalchemy import Connection, Engine, Select, func, select

from mocapqa.errors import NotFoundError
from mocapqa.store.tables import runs, shoots, take_qa

__all__ = ["run_limits_model", "shoot_limits_model", "stale_limits_counts", "stale_limits_runs"]


def shoot_limits_model(conn: Connection, shoot_id: str) -> str:
    """The name of a shoot's limits model.

    Raises
    ------
    NotFoundError
        When no shoot has that id.
    """
    found = conn.execute(select(shoots.c.limits_model).where(shoots.c.id == shoot_id)).scalar()
    if found is None:
        raise NotFoundError(f"Expected shoot {shoot_id!r} to exist, got none")
    return str(found)


def run_limits_model(conn: Connection, requested: str | None, shoot_id: str | None) -> str:
    """The limits model a new run of a take checks with: ``requested`` when the run's options
    name one, else the model of the take's shoot, else (a take outside any shoot) the catalog's
    default. The name is recorded with the run, so its options say which model it used.

    Raises
    ------
    NotFoundError
        When ``shoot_id`` names no shoot.
    """
    if requested is not None:
        return requested
    if shoot_id:
        return shoot_limits_model(conn, shoot_id)
    # Imported here: the catalog loads the limits stack, which the batch client (it records
    # runs through this store) never needs otherwise.
    from mocapqa.limits.catalog import DEFAULT_MODEL

    return DEFAULT_MODEL


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
