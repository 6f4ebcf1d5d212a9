"""Joint-limits models: the choosable ones, and a shoot's choice (admins only)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Depends, Request

from mocapqa.api.auth import Principal, audit, require
from mocapqa.api.deps import ClientDep, ServicesDep, run_places
from mocapqa.api.errors import responses
from mocapqa.api.shoot_schemas import LimitsModelIn, LimitsModelOut, LimitsRerunsOut, ShootOut
from mocapqa.limits.catalog import ModelCatalog
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.limits_runs import stale_limits_runs
from mocapqa.store.roles import Action
from mocapqa.store.shoots import ShootStore

__all__ = ["router"]

router = APIRouter(tags=["limits"])
"""Routes of this resource, included under ``/api/v1``."""
Chooser = Annotated[Principal, Depends(require(Action.CHOOSE_LIMITS_MODEL))]


def _catalog(services: ServicesDep) -> ModelCatalog:
    return ModelCatalog.of_data_folder(services.files.root)


@router.get("/limits-models", responses=responses(401))
def list_limits_models(services: ServicesDep) -> list[LimitsModelOut]:
    """The joint-limits models a shoot can use: the default choice, the shipped files and the
    models registered in the data folder (`mocapqa limits register`)."""
    return [LimitsModelOut(**entry.to_json()) for entry in _catalog(services).entries()]


@router.put("/shoots/{shoot_id}/limits-model", responses=responses(401, 403, 404, 413, 422))
def choose_limits_model(
    request: Request, principal: Chooser, shoot_id: str, body: LimitsModelIn, services: ServicesDep
) -> ShootOut:
    """Choose the joint-limits model of a shoot (admins only): the runs of its takes started
    from now on use it (runs already made keep theirs: the shoot's `limits_stale_takes` counts
    the takes whose latest run used another model, `POST /shoots/{id}/limits-reruns` runs
    them again). 422 for a name that is not in `GET /limits-models`."""
    store = ShootStore(services.repository.engine)
    store.require(shoot_id)
    name = _catalog(services).require(body.name)
    before = store.limits_model(shoot_id)
    shoot = store.set_limits_model(shoot_id, name)
    audit(request, principal, "shoot_limits_model", shoot_id, f"{before} → {name}")
    return ShootOut(**shoot)


@router.post("/shoots/{shoot_id}/limits-reruns", responses=responses(401, 403, 404, 413, 422, 429))
def rerun_stale_limits(
    request: Request,
    principal: Chooser,
    shoot_id: str,
    services: ServicesDep,
    client: ClientDep,
) -> LimitsRerunsOut:
    """Run again, with the shoot's joint-limits model, every motion take whose latest run used
    another model (admins only; the shoot's `limits_stale_takes`). Each new run keeps the other
    options of the take's latest run and joins the caller's line of the run queue, up to
    `max_queued_runs_per_user` queued at once: `remaining` says how many are left for a later
    request (429 when the caller has no free place and there is something to run)."""
    store = ShootStore(services.repository.engine)
    model = store.limits_model(shoot_id)
    stale = stale_limits_runs(services.repository.engine, shoot_id)
    queued = []
    if stale:
        with run_places(services, client, len(stale)) as free:
            for take_id, used in stale[:free]:
                options = AnalysisOptions.from_json({**used, "limits_model": None})
                run_id = services.repository.add_run(take_id, options.to_json())
                services.runner.submit(run_id, client=client)
                queued.append({"take_id": take_id, "run_id": run_id})
    detail = f"{len(queued)} run(s) with {model}, {len(stale) - len(queued)} left"
    audit(request, principal, "shoot_limits_reruns", shoot_id, detail)
    return LimitsRerunsOut(limits_model=model, queued=queued, remaining=len(stale) - len(queued))
