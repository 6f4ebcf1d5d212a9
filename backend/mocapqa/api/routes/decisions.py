"""Reviewers' accept / reject decisions on a run's twist intervals, and the decided take."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Depends, Path, Request
from fastapi.responses import Response

from mocapqa.api.auth import Principal, audit, client_address, require
from mocapqa.api.decision_schemas import DecisionIn, DecisionOut, DecisionsOut
from mocapqa.api.deps import ServicesDep
from mocapqa.api.disposition import attachment, download_stem
from mocapqa.api.errors import responses
from mocapqa.core.text import display_name
from mocapqa.errors import NotFoundError
from mocapqa.jobs.accepted import decided_bvh, decided_motion, run_intervals, with_decisions
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.decisions import IntervalDecisions
from mocapqa.store.roles import Action

__all__ = ["router"]

router = APIRouter(prefix="/runs/{run_id}", tags=["decisions"])
"""Routes of this resource, included under ``/api/v1``."""


def get_decisions(services: ServicesDep) -> IntervalDecisions:
    """The decision store on the repository's database."""
    return IntervalDecisions(services.repository.engine)


DecisionsDep = Annotated[IntervalDecisions, Depends(get_decisions)]


def _done_run(run_id: str, services: ServicesDep) -> dict[str, Any]:
    return services.repository.require_done(run_id)


DoneRunDep = Annotated[dict[str, Any], Depends(_done_run)]


def _out(row: dict[str, Any]) -> DecisionOut:
    return DecisionOut.model_validate({**row, "reviewer": display_name(str(row["reviewer"]))})


@router.get("/decisions", responses=responses(401, 404, 409))
def list_decisions(run: DoneRunDep, services: ServicesDep, decisions: DecisionsDep) -> DecisionsOut:
    """The run's twist intervals with their newest decision, and every decision (newest
    first). 409 for a keypoint take or a run without the twist check."""
    run_id = str(run["id"])
    intervals = run_intervals(services.files, run_id)
    return DecisionsOut.model_validate(
        {
            "run_id": run_id,
            "apply": AnalysisOptions.from_json(run["options"]).twist_apply,
            "intervals": with_decisions(intervals, decisions.latest(run_id)),
            "history": [_out(r) for r in decisions.history(run_id)],
        }
    )


@router.post(
    "/intervals/{interval_id}/decisions",
    status_code=201,
    responses=responses(401, 403, 404, 409, 413),
)
def add_decision(
    request: Request,
    principal: Annotated[Principal, Depends(require(Action.REVIEW))],
    run: DoneRunDep,
    interval_id: Annotated[int, Path(ge=0, le=2**31 - 1)],
    body: DecisionIn,
    services: ServicesDep,
    decisions: DecisionsDep,
) -> DecisionOut:
    """Accept or reject one twist interval; the newest decision per interval counts, every
    one is kept, with the reviewer and the client's address (as the audit log has it)."""
    run_id = str(run["id"])
    known = {int(i["id"]) for i in run_intervals(services.files, run_id)}
    if interval_id not in known:
        raise NotFoundError(
            f"Expected a twist interval id of run {run_id} ({len(known)} interval(s)), "
            f"got {interval_id}"
        )
    # The reviewer is who is signed in; a body's ``reviewer`` is ignored. The client is the
    # request's address (not the run-quota key, ``user:N`` for a signed-in user).
    address = client_address(request)
    row = decisions.add(run_id, interval_id, body.decision, body.note, principal.name, address)
    audit(request, principal, "decision", run_id, f"interval {interval_id}: {body.decision}")
    return _out(row)


@router.get(
    "/decisions/bvh",
    response_class=Response,
    responses={200: {"content": {"text/plain": {}}}, **responses(401, 404, 409)},
)
def download_decided(run: DoneRunDep, services: ServicesDep, decisions: DecisionsDep) -> Response:
    """The raw take with exactly the accepted corrections, as BVH: the levels of accepted
    intervals removed; an undecided interval follows the run's ``twist_apply`` choice. No
    motion filter is applied."""
    take = services.repository.get_take(str(run["take_id"]))
    motion = decided_motion(
        services.files,
        run,
        take,
        decisions.latest(str(run["id"])),
        services.settings.read_limits,
    )
    return Response(
        decided_bvh(motion),
        media_type="text/plain",
        headers=attachment(f"{download_stem(take)}.decided.bvh"),
    )
