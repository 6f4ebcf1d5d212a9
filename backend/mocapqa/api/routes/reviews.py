"""Review decisions per take, kept as history (who, when, status, notes)."""

from __future__ import annotations

from fastapi import APIRouter

from mocapqa.api.deps import ServicesDep, TakeDep
from mocapqa.api.errors import responses
from mocapqa.api.schemas import ReviewIn, ReviewOut
from mocapqa.api.views import review_out
from mocapqa.core.text import display_name

__all__ = ["router"]

router = APIRouter(prefix="/takes/{take_id}/reviews", tags=["reviews"])
"""Routes of this resource, included under ``/api/v1``."""


@router.get("", responses=responses(404))
def list_reviews(take: TakeDep, services: ServicesDep) -> list[ReviewOut]:
    """A take's review history, newest first."""
    return [review_out(r) for r in services.repository.list_reviews(str(take["id"]))]


@router.post("", status_code=201, responses=responses(403, 404, 413))
def add_review(take: TakeDep, review: ReviewIn, services: ServicesDep) -> ReviewOut:
    """Record a review decision; the newest one is the take's review status."""
    reviewer = display_name(review.reviewer) or "anonymous"
    row = services.repository.add_review(str(take["id"]), review.status, review.notes, reviewer)
    return review_out(row)
