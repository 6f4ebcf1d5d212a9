"""Reviewers' accept / reject decisions on a run's twist intervals or swaps and its foot locks,
and the decided take."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Depends, Path, Query, Request
from fastapi.responses import Response
from pydantic import Field

from mocapqa.api.auth import Principal, audit, client_address, require
from mocapqa.api.decision_schemas import DecisionIn, DecisionOut, DecisionsOut, LockDecisionOut
from mocapqa.api.deps import Services, ServicesDep
from mocapqa.api.disposition import attachment, download_stem
from mocapqa.api.errors import responses
from mocapqa.core.text import display_name
from mocapqa.errors import ConflictError, NotFoundError
from mocapqa.io.guards import ReadLimits
from mocapqa.jobs.accepted import (
    decided_bvh,
    decided_motion,
    run_decidables,
    run_intervals,
    run_locks,
    run_swaps,
    with_decisions,
)
from mocapqa.jobs.decided_feet import lock_kept
from mocapqa.jobs.decided_markers import decided_c3d, decided_trc
from mocapqa.pipeline.marker_step import MARKER_APPLY
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.decisions import DecidedItem, IntervalDecisions
from mocapqa.store.files import FileStore
from mocapqa.store.roles import Action

__all__ = ["HISTORY_MAX_LIMIT", "PagedDecisionsOut", "router"]

HISTORY_MAX_LIMIT = 500
"""The most decisions of each history one answer of ``GET /runs/{id}/decisions`` holds."""

router = APIRouter(prefix="/runs/{run_id}", tags=["decisions"])
"""Routes of this resource, included under ``/api/v1``."""


def get_decisions(services: ServicesDep) -> IntervalDecisions:
    """The decision store on the repository's database."""
    return IntervalDecisions(services.repository.engine)


DecisionsDep = Annotated[IntervalDecisions, Depends(get_decisions)]


def _done_run(run_id: str, services: ServicesDep) -> dict[str, Any]:
    return services.repository.require_done(run_id)


DoneRunDep = Annotated[dict[str, Any], Depends(_done_run)]


class PagedDecisionsOut(DecisionsOut):
    """:class:`DecisionsOut` whose histories are one page (``limit`` newest after ``offset``),
    with the length of each whole history."""

    history: list[DecisionOut] = Field(
        description="The decisions on a twist interval or swap, newest first: one page "
        "(``limit`` after the ``offset`` newest)"
    )
    history_total: int = Field(
        description="Decisions on the run's twist intervals or swaps; ``history`` is a page"
    )
    lock_history: list[LockDecisionOut] = Field(
        [], description="The decisions on a foot lock, newest first: a page as ``history`` is"
    )
    lock_history_total: int = Field(
        description="Decisions on the run's foot locks; ``lock_history`` is a page"
    )


def _out(row: dict[str, Any], item: DecidedItem) -> DecisionOut:
    reviewer = display_name(str(row["reviewer"]))
    return DecisionOut.model_validate({**row, "item": item, "reviewer": reviewer})


def _lock_out(row: dict[str, Any]) -> LockDecisionOut:
    reviewer = display_name(str(row["reviewer"]))
    return LockDecisionOut.model_validate({**row, "item": "lock", "reviewer": reviewer})


@dataclass(frozen=True, slots=True)
class _Review:
    """Who decides on which run, and the stores a decision is checked against and kept in."""

    request: Request
    principal: Principal
    run: dict[str, Any]
    services: Services
    decisions: IntervalDecisions


def _review(
    request: Request,
    principal: Annotated[Principal, Depends(require(Action.REVIEW))],
    run: DoneRunDep,
    services: ServicesDep,
    decisions: DecisionsDep,
) -> _Review:
    return _Review(request, principal, run, services, decisions)


ReviewDep = Annotated[_Review, Depends(_review)]


def _decide(review: _Review, item: DecidedItem, item_id: int, body: DecisionIn) -> DecisionOut:
    """Append a decision on a twist interval or swap of the run, by who is signed in (a body's
    ``reviewer`` is ignored), from the request's address (not the run-quota key, ``user:N``
    for a signed-in user), and audit it.

    Raises
    ------
    NotFoundError
        If the run has no such interval or swap, or the run or its take is gone.
    ConflictError
        If the run's take is approved.
    InputError
        For a note longer than :data:`~mocapqa.store.decisions.NOTE_MAX_CHARS`.
    """
    run_id = str(review.run["id"])
    listed = run_intervals if item == "interval" else run_swaps
    known = {int(i["id"]) for i in listed(review.services.files, run_id)}
    if item_id not in known:
        name = "twist interval" if item == "interval" else "swap"
        raise NotFoundError(
            f"Expected a {name} id of run {run_id} ({len(known)} {name}(s)), got {item_id}"
        )
    request, principal = review.request, review.principal
    address = client_address(request)
    row = review.decisions.add(run_id, item_id, body.decision, body.note, principal.name, address)
    audit(request, principal, "decision", run_id, f"{item} {item_id}: {body.decision}")
    return _out(row, item)


_DECISION_POST: dict[str, Any] = {
    "status_code": 201,
    "responses": responses(401, 403, 404, 409, 413),
}


@router.get("/decisions", responses=responses(401, 404, 409))
def list_decisions(
    run: DoneRunDep,
    services: ServicesDep,
    decisions: DecisionsDep,
    limit: Annotated[
        int, Query(ge=1, le=HISTORY_MAX_LIMIT, description="Decisions per history page")
    ] = 200,
    offset: Annotated[
        int, Query(ge=0, le=2**31 - 1, description="Newest decisions before the page")
    ] = 0,
) -> PagedDecisionsOut:
    """The run's twist intervals (a motion take) or swaps (a marker take) and its foot locks
    (the skate findings of its feet step) with their newest decision (whatever the length of
    the history), and a page of each decision history: ``limit`` decisions, newest first,
    after the ``offset`` newest; ``history_total`` and ``lock_history_total`` count each
    whole history. 409 for a run with none of these to decide."""
    run_id = str(run["id"])
    item, items, locks = run_decidables(services.files, run_id)
    decided = with_decisions(items, decisions.latest(run_id))
    latest_locks = decisions.latest_locks(run_id)
    options = AnalysisOptions.from_json(run["options"])
    return PagedDecisionsOut.model_validate(
        {
            "run_id": run_id,
            "item": item,
            "apply": options.twist_apply if item == "interval" else MARKER_APPLY,
            "lock_apply": options.feet_apply,
            "intervals": decided if item == "interval" else [],
            "swaps": decided if item == "swap" else [],
            "history": [
                _out(r, item) for r in decisions.history(run_id, limit=limit, offset=offset)
            ],
            "history_total": decisions.count(run_id),
            "locks": [
                {
                    **lock,
                    "decision": latest_locks.get(str(lock["id"])),
                    "run_applied": bool(lock.get("applied")),
                    "applied": lock_kept(lock, latest_locks.get(str(lock["id"]))),
                }
                for lock in locks
            ],
            "lock_history": [
                _lock_out(r) for r in decisions.history(run_id, "lock", limit, offset)
            ],
            "lock_history_total": decisions.count(run_id, "lock"),
        }
    )


@router.post("/intervals/{interval_id}/decisions", **_DECISION_POST)
def add_decision(
    review: ReviewDep,
    interval_id: Annotated[int, Path(ge=0, le=2**31 - 1)],
    body: DecisionIn,
) -> DecisionOut:
    """Accept or reject one twist interval; the newest decision per interval counts, every
    one is kept, with the reviewer and the client's address (as the audit log has it)."""
    return _decide(review, "interval", interval_id, body)


@router.post("/swaps/{swap_id}/decisions", **_DECISION_POST)
def add_swap_decision(
    review: ReviewDep,
    swap_id: Annotated[int, Path(ge=0, le=2**31 - 1)],
    body: DecisionIn,
) -> DecisionOut:
    """Accept or reject one swap of a marker run (its ``id`` in the run's findings), kept as
    the interval decisions are."""
    return _decide(review, "swap", swap_id, body)


@router.post("/feet/{lock_id}/decisions", **_DECISION_POST)
def add_lock_decision(
    review: ReviewDep,
    lock_id: Annotated[str, Path(min_length=1, max_length=64)],
    body: DecisionIn,
) -> LockDecisionOut:
    """Accept or reject the foot lock of one skate finding of the run (its ``id`` in the run's
    findings, ``skate-left-120``), kept as the interval decisions are. The decided download
    locks the accepted ones, and the undecided ones the run locked (its ``feet_apply``; none
    by default). 409 for a run without the feet check."""
    run_id = str(review.run["id"])
    locks = run_locks(review.services.files, run_id)
    if locks is None:
        raise ConflictError(
            f"Expected a run with the feet check to decide on foot locks, got run {run_id} "
            "without it: start a run with 'feet' in checks"
        )
    known = [str(lock["id"]) for lock in locks]
    if lock_id not in known:
        raise NotFoundError(
            f"Expected the id of a skate finding of run {run_id} ({len(known)} foot lock(s)"
            f"{': ' + ', '.join(known[:6]) if known else ''}), got {lock_id!r}"
        )
    request, principal = review.request, review.principal
    address = client_address(request)
    row = review.decisions.add_lock(
        run_id, lock_id, body.decision, body.note, principal.name, address
    )
    audit(request, principal, "decision", run_id, f"lock {lock_id}: {body.decision}")
    return _lock_out(row)


@router.get(
    "/decisions/bvh",
    response_class=Response,
    responses={200: {"content": {"text/plain": {}}}, **responses(401, 404, 409)},
)
def download_decided(run: DoneRunDep, services: ServicesDep, decisions: DecisionsDep) -> Response:
    """The raw take with exactly the accepted corrections, as BVH: the levels of accepted
    intervals removed (an undecided interval follows the run's ``twist_apply`` choice), then
    the kept foot locks solved on the legs (accepted, or undecided and locked by the run's
    ``feet_apply``). No motion filter is applied."""
    return _decided_download(run, services, decisions, _decided_bvh, "bvh")


Content = Callable[
    [FileStore, dict[str, Any], dict[str, Any], dict[int, str], ReadLimits | None, dict[str, str]],
    bytes,
]
"""A decided take's bytes from the run's files, the run, its take, the newest decisions on its
corrections, the reading limits and the newest decisions on its foot locks."""


def _decided_bvh(
    files: FileStore,
    run: dict[str, Any],
    take: dict[str, Any],
    latest: dict[int, str],
    limits: ReadLimits | None,
    locks: dict[str, str],
) -> bytes:
    return decided_bvh(decided_motion(files, run, take, latest, limits, locks))


@router.get(
    "/decisions/c3d",
    response_class=Response,
    responses={200: {"content": {"application/octet-stream": {}}}, **responses(401, 404, 409)},
)
def download_decided_c3d(
    run: DoneRunDep, services: ServicesDep, decisions: DecisionsDep
) -> Response:
    """The C3D of a marker take with exactly the accepted swaps repaired (an undecided swap
    follows the run's ``applied``), then its gaps filled by the run's rule (the confident
    fills), as the run's ``corrected.c3d`` is written, then the kept foot locks pinned
    (accepted, or undecided and locked by the run's ``feet_apply``). No filter."""
    return _decided_download(run, services, decisions, decided_c3d, "c3d")


@router.get(
    "/decisions/trc",
    response_class=Response,
    responses={200: {"content": {"text/plain": {}}}, **responses(401, 404, 409)},
)
def download_decided_trc(
    run: DoneRunDep, services: ServicesDep, decisions: DecisionsDep
) -> Response:
    """The TRC of a marker take (a TRC take, or a C3D take for OpenSim) decided as the C3D is:
    the accepted swaps repaired (an undecided swap follows the run's ``applied``), its gaps
    filled by the run's rule, the kept foot locks pinned; the take's rate, unit, marker
    names and frame numbers. TRC has no residual: the run's ``gap`` findings list the filled
    samples; a sample still missing is ``NaN``. 409 for a motion or keypoint take. No
    filter."""
    return _decided_download(run, services, decisions, decided_trc, "trc")


_MEDIA_TYPES = {"bvh": "text/plain", "c3d": "application/octet-stream", "trc": "text/plain"}


def _decided_download(
    run: dict[str, Any],
    services: Services,
    decisions: IntervalDecisions,
    content: Content,
    suffix: Literal["bvh", "c3d", "trc"],
) -> Response:
    """The decided take of a run as an attachment ``<take>.decided.<suffix>``: ``content``
    of the run's files, the run, its take, the newest decisions, the reading limits and the
    newest lock decisions."""
    take = services.repository.get_take(str(run["take_id"]))
    run_id = str(run["id"])
    data = content(
        services.files,
        run,
        take,
        decisions.latest(run_id),
        services.settings.read_limits,
        decisions.latest_locks(run_id),
    )
    return Response(
        data,
        media_type=_MEDIA_TYPES[suffix],
        headers=attachment(f"{download_stem(take)}.decided.{suffix}"),
    )
