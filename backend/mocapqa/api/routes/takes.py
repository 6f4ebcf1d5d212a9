"""Takes: upload, list (paged, filtered), get, delete, thumbnail."""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Depends, File, Form, Query, Request, Response, UploadFile

from mocapqa.api.auth import Principal, audit, require, require_owner
from mocapqa.api.deps import ClientDep, ServicesDep, TakeDep, run_places
from mocapqa.api.errors import responses
from mocapqa.api.schemas import TakeCreatedOut, TakeDetailOut, TakeOut, TakePageOut
from mocapqa.api.views import review_out, run_out, take_fields
from mocapqa.core.bounds import MAX_FPS, MIN_FPS
from mocapqa.core.keypoints import LENGTH_UNITS
from mocapqa.jobs.intake import ingest_take
from mocapqa.jobs.reading_record import reading_of
from mocapqa.jobs.run_folder import RunFolder
from mocapqa.jobs.thumbnails import thumbnail_svg
from mocapqa.pipeline.loading import ReadOptions
from mocapqa.store.repository import ReviewStatus, RunStatus
from mocapqa.store.roles import Action

__all__ = ["router"]

router = APIRouter(prefix="/takes", tags=["takes"])
"""Routes of this resource, included under ``/api/v1``."""
MAX_OFFSET = 2**31 - 1
"""Largest page offset (the schema refuses more with 422)."""
LengthUnit = Literal[LENGTH_UNITS]  # type: ignore[valid-type]
"""A keypoint length unit: another is a 422 naming ``body.length_unit``."""


@router.post("", status_code=201, responses=responses(401, 403, 413, 415, 429))
def upload_take(
    request: Request,
    principal: Annotated[Principal, Depends(require(Action.UPLOAD))],
    services: ServicesDep,
    client: ClientDep,
    file: Annotated[UploadFile, File()],
    fps: Annotated[
        float | None,
        Form(
            ge=MIN_FPS,
            le=MAX_FPS,
            allow_inf_nan=False,
            description="Frame rate (frames per second), for formats that do not store one.",
        ),
    ] = None,
    length_unit: Annotated[
        LengthUnit | None,
        Form(
            description="Unit of keypoint coordinates (m, cm, mm, in, px, normalized), for "
            "formats that do not store one."
        ),
    ] = None,
    root_translation: Annotated[
        Literal["auto", "add", "replace"],
        Form(description="BVH root position: detect, add to the root OFFSET, or replace it."),
    ] = "auto",
) -> TakeCreatedOut:
    """Upload a take (multipart field ``file``); its analysis starts with default options.

    Optional form fields say how to read what the file leaves open: ``fps`` and
    ``length_unit`` (OpenPose, MediaPipe, NPY, CSV without times) and ``root_translation``
    (BVH). The take's ``reading`` says what was used and assumed.

    Refused before the body is read: more than ``max_upload_mb`` (413), a cross-site browser
    request (403), too many uploads or queued runs from this client (429, ``Retry-After``).
    Refused before parsing: a take beyond the read limits (413, naming the setting). Refused
    at the request: an ``fps`` that is not finite or not from 0.1 to 100,000 (422 naming
    ``body.fps``, :mod:`mocapqa.core.bounds`); a ``file`` part without a file name (422 naming
    ``body.file``); a file's own frame rate meets the same bounds when it is read (422 naming
    ``fps``).
    """
    with run_places(services, client):
        max_bytes = int(services.settings.max_upload_mb * 1_000_000)
        take_id, run_id = ingest_take(
            file.file,
            file.filename or "take",
            services.repository,
            services.files,
            services.runner,
            max_bytes,
            read=ReadOptions(fps, length_unit, root_translation),
            limits=services.settings.read_limits,
            client=client,
            owner_id=principal.user_id,
        )
    audit(request, principal, "upload", take_id, f"{file.filename or 'take'} run {run_id}")
    row = services.repository.get_take(take_id)
    reading = reading_of(services.files, take_id)
    return TakeCreatedOut(**take_fields(row), run_id=run_id, reading=reading)


@router.get("", responses=responses(401))
def list_takes(
    services: ServicesDep,
    limit: Annotated[int, Query(ge=1, le=500)] = 50,
    offset: Annotated[int, Query(ge=0, le=MAX_OFFSET)] = 0,
    status: RunStatus | None = None,
    review_status: ReviewStatus | None = None,
) -> TakePageOut:
    """A page of takes, newest first, optionally filtered by run or review status."""
    rows, total = services.repository.list_takes(limit, offset, status, review_status)
    items = [TakeOut(**take_fields(r)) for r in rows]
    return TakePageOut(items=items, total=total, limit=limit, offset=offset)


@router.get("/{take_id}", responses=responses(401, 404))
def get_take(take: TakeDep, services: ServicesDep) -> TakeDetailOut:
    """One take with its runs (oldest first) and its review history (newest first)."""
    take_id = str(take["id"])
    return TakeDetailOut(
        **take_fields(take),
        runs=[run_out(r) for r in services.repository.list_runs(take_id)],
        reviews=[review_out(r) for r in services.repository.list_reviews(take_id)],
        reading=reading_of(services.files, take_id),
    )


@router.delete("/{take_id}", status_code=204, responses=responses(401, 403, 404, 413))
def delete_take(
    request: Request,
    principal: Annotated[Principal, Depends(require(Action.DELETE_OWN))],
    take: TakeDep,
    services: ServicesDep,
) -> Response:
    """Delete a take, its runs (a queued or running one is stopped), reviews and files: its
    owner or an admin."""
    take_id = str(take["id"])
    require_owner(principal, take.get("owner_id"), f"take {take_id}")
    run_ids = services.repository.delete_take(take_id)
    services.runner.cancel(run_ids)
    services.files.remove_take(take_id, run_ids)
    audit(request, principal, "delete", take_id, str(take["name"]))
    return Response(status_code=204)


@router.get(
    "/{take_id}/thumbnail",
    response_class=Response,
    responses={
        200: {"content": {"image/png": {}, "image/svg+xml": {}}, "description": "A picture"},
        **responses(401, 404),
    },
)
def thumbnail(take: TakeDep, services: ServicesDep) -> Response:
    """A small picture of the take: the rendered PNG of the latest run, else an SVG (a
    placeholder until a run has points; a line drawing when rendering is unavailable)."""
    run_id = take.get("latest_run_id")
    if run_id:
        png = RunFolder.of(services.files, str(run_id)).thumbnail
        if png.is_file():
            return Response(
                png.read_bytes(), media_type="image/png", headers={"Cache-Control": "max-age=60"}
            )
    body = thumbnail_svg(services.files, str(run_id) if run_id else None, str(take["name"]))
    return Response(body, media_type="image/svg+xml", headers={"Cache-Control": "max-age=60"})
