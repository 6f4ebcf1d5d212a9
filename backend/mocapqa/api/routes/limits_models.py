"""Joint-limits models: the choosable ones, and a shoot's choice (admins only)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Depends, Request

from mocapqa.api.auth import Principal, audit, require
from mocapqa.api.deps import ServicesDep
from mocapqa.api.errors import responses
from mocapqa.api.shoot_schemas import LimitsModelIn, LimitsModelOut, ShootOut
from mocapqa.limits.catalog import ModelCatalog
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


@router.put("/shoots/{shoot_id}/limits-model", responses=responses(401, 403, 404, 422))
def choose_limits_model(
    request: Request, principal: Chooser, shoot_id: str, body: LimitsModelIn, services: ServicesDep
) -> ShootOut:
    """Choose the joint-limits model of a shoot (admins only): the runs of its takes started
    from now on use it (runs already made keep theirs). 422 for a name that is not in
    `GET /limits-models`."""
    store = ShootStore(services.repository.engine)
    store.require(shoot_id)
    name = _catalog(services).require(body.name)
    before = store.limits_model(shoot_id)
    shoot = store.set_limits_model(shoot_id, name)
    audit(request, principal, "shoot_limits_model", shoot_id, f"{before} → {name}")
    return ShootOut(**shoot)
