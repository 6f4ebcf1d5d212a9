"""Review decisions per take, kept as history (who, when, status, notes)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Depends, Request

from mocapqa.api.auth import Principal, audit, require
from mocapqa.api.deps import ServicesDep, TakeDep
from mocapqa.api.errors import responses
from mocapqa.api.schemas import ReviewIn, ReviewOut
from mocapqa.api.views import review_out
from mocapqa.store.roles import Action

__all__ = ["router"]

router = APIRouter(prefix="/takes/{take_id}/reviews", tags=["reviews"])
"""Routes of this resource, included under ``/api/v1``."""


@router.get("", responses=responses(401, 404))
def list_reviews(take: TakeDep, services: ServicesDep) -> list[ReviewOut]:
    """A take's review history, newest first."""
    return [review_out(r) for r in services.repository.list_reviews(str(take["id"]))]


@router.post("", status_code=201, responses=responses(401, 403, 404, 413))
def add_review(
    request: Request,
    principal: Annotated[Principal, Depends(require(Action.REVIEW))],
    take: TakeDep,
    review: ReviewIn,
    services: ServicesDep,
) -> ReviewOut:
    """Record a review decision by the signed-in user (the reviewer is who is signed in,
    never a field of the body); the newest one is the take's review status."""
    take_id = str(take["id"])
    row = services.repository.add_review(
        take_id, review.status, review.notes, principal.name, principal.user_id
    )
    audit(request, principal, "review", take_id, review.status)
    return review_out(row)
