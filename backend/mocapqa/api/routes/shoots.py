"""Shoots: create, list, rename, delete; import files and archives; the take table, heat map,
review queue, progress and summary export."""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterator
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Depends, File, Query, Request, Response, UploadFile
from fastapi.responses import StreamingResponse

from mocapqa.api.auth import Principal, audit, require, require_owner
from mocapqa.api.deps import ClientDep, ServicesDep
from mocapqa.api.disposition import attachment
from mocapqa.api.errors import responses
from mocapqa.api.http_guards import STAGING_STATE
from mocapqa.api.shoot_schemas import (
    HeatmapOut,
    ImportOut,
    NextTakeOut,
    ProgressOut,
    ShootIn,
    ShootOut,
    ShootTakeOut,
    ShootTakePageOut,
)
from mocapqa.errors import InputError, OptionError
from mocapqa.jobs.batch_output import COLUMNS
from mocapqa.jobs.shoot_import import ImportLimits, import_uploads
from mocapqa.store.qa import FEET_COLUMNS
from mocapqa.store.repository import ReviewStatus, RunStatus
from mocapqa.store.roles import Action
from mocapqa.store.shoot_pages import SORT_COLUMNS, TakeFilter
from mocapqa.store.shoots import ShootStore

__all__ = ["EXPORT_COLUMNS", "HEATMAP_MAX_TAKES", "MAX_OFFSET", "router", "take_filter"]

# A shoot's maker (its owner) renames and deletes it, as a take's uploader deletes the take;
# admins may do both to any shoot, and are the only ones for shoots without an owner.
Maker = Annotated[Principal, Depends(require(Action.UPLOAD))]
Deleter = Annotated[Principal, Depends(require(Action.DELETE_OWN))]
HEATMAP_MAX_TAKES = 1000
"""Most takes in one page of the heat map."""
MAX_OFFSET = 10_000_000
"""Largest page offset the take table and heat map accept (far beyond any shoot)."""
router = APIRouter(prefix="/shoots", tags=["shoots"])
"""Routes of this resource, included under ``/api/v1``."""


def _store(services: ServicesDep) -> ShootStore:
    return ShootStore(services.repository.engine)


ShootSort = Literal[SORT_COLUMNS]  # type: ignore[valid-type]


@router.post("", status_code=201, responses=responses(401, 403, 409, 413))
def create_shoot(
    request: Request, principal: Maker, body: ShootIn, services: ServicesDep
) -> ShootOut:
    """Create an empty shoot, owned by the signed-in user."""
    shoot = _store(services).create(body.name, principal.user_id)
    audit(request, principal, "shoot_create", str(shoot["id"]), str(shoot["name"]))
    return ShootOut(**shoot)


@router.get("", responses=responses(401))
def list_shoots(services: ServicesDep) -> list[ShootOut]:
    """Every shoot, by name, with its take counts per run status and per review status."""
    return [ShootOut(**row) for row in _store(services).list_all()]


@router.get("/{shoot_id}", responses=responses(401, 404))
def get_shoot(shoot_id: str, services: ServicesDep) -> ShootOut:
    """One shoot with its counts."""
    return ShootOut(**_store(services).get(shoot_id))


@router.patch("/{shoot_id}", responses=responses(401, 403, 404, 409, 413))
def rename_shoot(
    request: Request, principal: Maker, shoot_id: str, body: ShootIn, services: ServicesDep
) -> ShootOut:
    """Rename a shoot: its owner or an admin (403 otherwise)."""
    store = _store(services)
    before = store.get(shoot_id)
    require_owner(principal, before["owner_id"], f"shoot {shoot_id}")
    shoot = store.rename(shoot_id, body.name)
    audit(request, principal, "shoot_rename", shoot_id, f"{before['name']} → {shoot['name']}")
    return ShootOut(**shoot)


@router.delete(
    "/{shoot_id}",
    status_code=204,
    responses=responses(401, 403, 404, 413),
)
def delete_shoot(
    request: Request,
    principal: Deleter,
    shoot_id: str,
    services: ServicesDep,
    confirm: Annotated[str, Query(description="The shoot's exact name, to confirm")] = "",
) -> Response:
    """Delete a shoot **with all its takes**, their runs (a queued or running one is
    stopped), reviews and files: its owner or an admin (403 otherwise), whoever uploaded the
    takes.

    ``confirm`` must repeat the shoot's name (422 otherwise, nothing deleted).
    """
    store = _store(services)
    shoot = store.get(shoot_id)
    require_owner(principal, shoot["owner_id"], f"shoot {shoot_id}")
    if confirm != shoot["name"]:
        raise InputError(
            f"Expected confirm={shoot['name']!r} to delete the shoot and its "
            f"{shoot['n_takes']} take(s), got {confirm!r}"
        )
    take_ids, run_ids = store.delete(shoot_id)
    services.runner.cancel(run_ids)  # queued and held runs never start; outputs removed
    for take_id in take_ids:
        services.files.remove_take(take_id, [])
    audit(request, principal, "shoot_delete", shoot_id, f"{shoot['name']}: {len(take_ids)} take(s)")
    return Response(status_code=204)


@router.post(
    "/{shoot_id}/takes",
    status_code=201,
    responses=responses(401, 403, 404, 413, 415, 429),
)
def import_takes(
    request: Request,
    principal: Maker,
    shoot_id: str,
    services: ServicesDep,
    client: ClientDep,
    files: Annotated[list[UploadFile], File(description="Takes, .zip or .tar.gz archives")],
) -> ImportOut:
    """Import takes into a shoot: many files at once (multipart field ``files``, repeated),
    archives unpacked member by member. Each take's analysis starts with default options.

    Non-motion archive members are listed as skipped, unreadable or unsafe ones (links,
    names leaving the archive) as failed with their error; the rest are kept, owned by the
    signed-in user (who may delete them, as takes uploaded one by one). A member larger than
    ``max_upload_mb`` is failed, cut while it is unpacked. An archive that would take the
    user's requests in progress past ``max_incoming_mb_per_user`` is 429 (413 when this
    request alone would), before it is unpacked.
    """
    _store(services).require(shoot_id)
    settings = services.settings
    limits = ImportLimits(
        max_upload_bytes=int(settings.max_upload_mb * 1_000_000),
        max_members=settings.archive_max_members,
        max_unpacked_bytes=int(settings.archive_max_unpacked_mb * 1_000_000),
        read=settings.read_limits,
    )
    report = import_uploads(
        [(f.file, f.filename or "take") for f in files],
        shoot_id,
        services.repository,
        services.files,
        services.runner,
        limits,
        client,
        principal.user_id,
        getattr(request.state, STAGING_STATE, None),
    )
    for take in report.created:
        audit(request, principal, "upload", take["take_id"], f"{take['name']} run {take['run_id']}")
    return ImportOut(created=report.created, skipped=report.skipped, failed=report.failed)


def take_filter(
    status: RunStatus | None = None,
    review_status: ReviewStatus | None = None,
    rig: str | None = None,
    min_score: Annotated[float | None, Query(ge=0, le=100)] = None,
    max_score: Annotated[float | None, Query(ge=0, le=100)] = None,
    has_findings: bool | None = None,
    search: Annotated[str | None, Query(max_length=255)] = None,
    has_skates: Annotated[
        bool | None,
        Query(description="Only takes whose feet check found a foot skate (true) or none (false)"),
    ] = None,
) -> TakeFilter:
    """The take table's filters from the query (the take table, the heat map and the
    exports share them); a ``min_score`` above ``max_score`` is 422, not an empty page."""
    if min_score is not None and max_score is not None and min_score > max_score:
        raise OptionError(
            "min_score", f"Expected min_score at most max_score ({max_score:g}), got {min_score:g}"
        )
    return TakeFilter(
        status, review_status, rig, min_score, max_score, has_findings, search, has_skates
    )


Filters = Annotated[TakeFilter, Depends(take_filter)]


@router.get("/{shoot_id}/takes", responses=responses(401, 404))
def list_shoot_takes(
    shoot_id: str,
    services: ServicesDep,
    filters: Filters,
    limit: Annotated[int, Query(ge=1, le=500)] = 50,
    offset: Annotated[int, Query(ge=0, le=MAX_OFFSET)] = 0,
    sort: ShootSort = "score",
    order: Literal["asc", "desc"] = "asc",
) -> ShootTakePageOut:
    """A page of the shoot's take table, sorted and filtered on the server."""
    rows, total = _store(services).page(shoot_id, limit, offset, sort, order == "desc", filters)
    return ShootTakePageOut(
        items=[ShootTakeOut(**r) for r in rows], total=total, limit=limit, offset=offset
    )


@router.get("/{shoot_id}/progress", responses=responses(401, 404))
def shoot_progress(shoot_id: str, services: ServicesDep) -> ProgressOut:
    """Takes per status and frames analysed; ``finished`` once nothing is queued or running."""
    return ProgressOut(**_store(services).progress(shoot_id))


@router.get("/{shoot_id}/heatmap", responses=responses(401, 404))
def shoot_heatmap(
    shoot_id: str,
    services: ServicesDep,
    filters: Filters,
    limit: Annotated[int, Query(ge=1, le=HEATMAP_MAX_TAKES, description="Takes per page")] = 200,
    offset: Annotated[int, Query(ge=0, le=MAX_OFFSET, description="Takes before the page")] = 0,
    sort: ShootSort = "score",
    order: Literal["asc", "desc"] = "asc",
) -> HeatmapOut:
    """Joint × take share of frames outside the joint limits, for a page of takes in the
    take table's order (``sort``, ``order``) and filters (the same parameters as the table);
    ``total`` takes match the filters, so a client pages through a shoot of any size
    ``limit`` takes at a time."""
    heat = _store(services).heatmap(shoot_id, limit, offset, sort, order == "desc", filters)
    return HeatmapOut(**heat, limit=limit, offset=offset)


@router.get("/{shoot_id}/next", responses=responses(401, 404))
def next_take(
    shoot_id: str,
    services: ServicesDep,
    after: Annotated[str | None, Query(description="Skip this take id")] = None,
) -> NextTakeOut:
    """The next take needing review: unreviewed, analysed, lowest QA score first."""
    row, remaining = _store(services).next_for_review(shoot_id, after)
    return NextTakeOut(take=ShootTakeOut(**row) if row else None, remaining=remaining)


EXPORT_COLUMNS = (
    "name",
    "status",
    *(name for name, _ in COLUMNS if name not in ("source", "status", "error")),
    "reviewer",
    *FEET_COLUMNS,
)
"""Columns of the shoot summary export, in order (the feet figures last, so the columns
before them keep their places)."""


_FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def _spreadsheet_text(value: Any) -> Any:
    """A CSV cell a spreadsheet shows as text: a string starting like a formula (a take named
    ``=HYPERLINK(...).bvh``) gets a leading apostrophe (OWASP's CSV-injection advice); numbers
    and other strings are left as they are."""
    if isinstance(value, str) and value.startswith(_FORMULA_STARTS):
        return "'" + value
    return value


def _export_rows(
    store: ShootStore, shoot_id: str, filters: TakeFilter, sort: str, descending: bool
) -> Iterator[dict[str, Any]]:
    for row in store.rows(shoot_id, filters=filters, sort=sort, descending=descending):
        yield {column: row.get(column) for column in EXPORT_COLUMNS}


@router.get(
    "/{shoot_id}/summary.{kind}",
    responses={
        **responses(401, 404),
        200: {"content": {"text/csv": {}, "application/json": {}}},
    },
    response_class=Response,
)
def export_summary(
    shoot_id: str,
    kind: Literal["csv", "json"],
    services: ServicesDep,
    filters: Filters,
    sort: ShootSort = "name",
    order: Literal["asc", "desc"] = "asc",
) -> Response:
    """The shoot's QA summary, one row per take (columns in docs/qa-summary.md): every take by
    name, or the take table's takes in its order when given its filters, ``sort`` and ``order``
    (what the dashboard's export links send)."""
    store = _store(services)
    shoot = store.get(shoot_id)
    disposition = attachment(f"{shoot['name']}.summary.{kind}")
    if kind == "json":
        rows = list(_export_rows(store, shoot_id, filters, sort, order == "desc"))
        about = {"shoot": shoot["name"], "filters": filters.chosen(), "sort": sort, "order": order}
        body = json.dumps({**about, "takes": rows}, default=str)
        return Response(body, media_type="application/json", headers=disposition)

    def lines() -> Iterator[str]:
        buffer = io.StringIO()
        writer = csv.DictWriter(buffer, list(EXPORT_COLUMNS))
        writer.writeheader()
        for row in _export_rows(store, shoot_id, filters, sort, order == "desc"):
            writer.writerow({k: _spreadsheet_text(v) for k, v in row.items()})
            yield buffer.getvalue()
            buffer.seek(0)
            buffer.truncate()

    return StreamingResponse(lines(), media_type="text/csv", headers=disposition)
