"""Analysis runs: start with options, status, result, point windows and downloads."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from fastapi import APIRouter, Depends, Query, Request
from fastapi.responses import FileResponse, Response

from mocapqa.api.auth import Principal, audit, require
from mocapqa.api.deps import ClientDep, Services, ServicesDep, TakeDep, run_places
from mocapqa.api.disposition import attachment, download_stem
from mocapqa.api.errors import responses
from mocapqa.api.frame_windows import Window, read_window, window_json, window_packed
from mocapqa.api.schemas import AnalysisOptionsIn, RunOut
from mocapqa.api.views import run_out
from mocapqa.errors import NotFoundError
from mocapqa.jobs.apply_ids import check_apply_ids
from mocapqa.jobs.reading_record import joint_parents_of, joints_of
from mocapqa.jobs.rendered import html_report
from mocapqa.jobs.run_folder import RunFolder
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.roles import Action

__all__ = ["router"]

router = APIRouter(tags=["runs"])
"""Routes of this resource, included under ``/api/v1``."""

MEDIA_TYPES = {
    "bvh": "text/plain",
    "csv": "text/csv",
    "trc": "text/plain",
    "c3d": "application/octet-stream",
    "report": "application/json",
}
"""The media type of each download kind (its file:
:data:`~mocapqa.jobs.run_folder.DOWNLOAD_FILES`)."""
MAX_FRAME = 2**31 - 1
"""Largest frame index or step a query may name (the schema refuses more with 422)."""


@router.post("/takes/{take_id}/runs", status_code=201, responses=responses(401, 403, 404, 413, 429))
def start_run(
    request: Request,
    principal: Annotated[Principal, Depends(require(Action.RUN))],
    take: TakeDep,
    services: ServicesDep,
    client: ClientDep,
    options: AnalysisOptionsIn | None = None,
) -> RunOut:
    """Start another analysis of a take with these options; earlier runs are kept.

    The options are checked here, against the filter registry, the take's kind, (for a
    ``mapping``) the take's joints and (for ``twist_apply`` ids) the take's newest run with twist
    intervals (422 naming the field), not when the run executes.
    """
    parsed = AnalysisOptions.from_json((options or AnalysisOptionsIn()).model_dump())
    parsed.check_take_kind(str(take["kind"]), float(take["fps"]) if take.get("fps") else None)
    take_id = str(take["id"])
    parsed.check_joints(
        joints_of(services.files, take_id), joint_parents_of(services.files, take_id)
    )
    check_apply_ids(services.repository, services.files, take_id, parsed.twist_apply)
    with run_places(services, client):
        run_id = services.repository.add_run(str(take["id"]), parsed.to_json())
        services.runner.submit(run_id, client=client)
    audit(request, principal, "run", str(take["id"]), f"run {run_id}")
    return run_out(services.repository.get_run(run_id))


@router.get("/runs/{run_id}", responses=responses(401, 404))
def get_run(run_id: str, services: ServicesDep) -> RunOut:
    """A run's status (queued | running | done | failed), progress (0–100 %) and step."""
    return run_out(services.repository.get_run(run_id))


@router.get(
    "/runs/{run_id}/result",
    responses={200: {"content": {"application/json": {}}}, **responses(401, 404, 409)},
)
def get_result(run_id: str, services: ServicesDep) -> Response:
    """The report: summary, steps, findings and the plotted series (409 until done)."""
    services.repository.require_done(run_id)
    path = services.files.existing(RunFolder.of(services.files, run_id).report, "the report")
    return Response(path.read_bytes(), media_type="application/json")


FrameStart = Annotated[int, Query(ge=0, le=MAX_FRAME)]
FrameStop = Annotated[int | None, Query(ge=1, le=MAX_FRAME)]
FrameStep = Annotated[int, Query(ge=1, le=MAX_FRAME)]
MaxFrames = Annotated[int, Query(ge=1, le=20_000)]


def frame_window(
    run_id: str,
    services: ServicesDep,
    start: FrameStart = 0,
    stop: FrameStop = None,
    step: FrameStep = 1,
    max_frames: MaxFrames = 1500,
) -> Window:
    """The frames a window route asks for, of a finished run's points (:func:`read_window`)."""
    return read_window(points_path(services, run_id), start, stop, step, max_frames)


WindowDep = Annotated[Window, Depends(frame_window)]


@router.get(
    "/runs/{run_id}/frames",
    responses={200: {"content": {"application/json": {}}}, **responses(401, 404, 409)},
)
def get_frames(window: WindowDep) -> Response:
    """Raw and corrected point positions for frames ``start:stop:step`` (file units).

    Motion takes also carry ``raw_rotations`` and ``corrected_rotations``: each point's world
    unit quaternion (scalar-last), by which the 3D view orients the bones.

    A missing point (a keypoint not detected in that frame) is ``[null, null, null]``.
    Keypoint takes also carry ``confidence`` (per point, 0–1, two decimals) and, when they were
    filtered, ``bridged`` (per point, 1 where the filter had no valid input and bridged it);
    marker takes the markers step checked, ``filled`` (per point, 1 on samples a gap fill
    wrote into the corrected take).

    The step grows so that at most ``max_frames`` frames and at most 3,000,000 values (frames
    × points × the arrays sent) come back; the answer states the frame indices it holds. A
    ``start`` at or past the last frame or a ``stop`` not after ``start`` is a 422 naming it.
    """
    return Response(window_json(window), media_type="application/json")


@router.get(
    "/runs/{run_id}/frames.f32",
    responses={200: {"content": {"application/octet-stream": {}}}, **responses(401, 404, 409)},
)
def get_frames_packed(window: WindowDep) -> Response:
    """The window of ``/frames`` as packed little-endian float32, for the 3D views.

    A uint32 ``n``, an ``n``-byte JSON header (``start``, ``step``, ``count``, ``n_frames``,
    ``points``, ``arrays`` as ``[name, components]``), then each array, shape
    (count, points, components), in that order; missing points are NaN, ``bridged`` and
    ``filled`` 0 or 1.
    A quarter of the bytes of the JSON and no parsing in the browser.
    """
    return Response(window_packed(window), media_type="application/octet-stream")


def points_path(services: Services, run_id: str) -> Path:
    """``points.npz`` of a finished run (404 for an unknown run, 409 until it is done)."""
    services.repository.require_done(run_id)
    return services.files.existing(RunFolder.of(services.files, run_id).points, "the points")


@router.get(
    "/runs/{run_id}/download/report.html",
    response_class=Response,
    responses={200: {"content": {"text/html": {}}}, **responses(401, 404, 409)},
)
def download_html_report(run_id: str, services: ServicesDep) -> Response:
    """The self-contained HTML QA report of a finished run (built on first request)."""
    run = services.repository.require_done(run_id)
    take = services.repository.get_take(str(run["take_id"]))
    body = html_report(services.files, run_id, take, services.renderer)
    return Response(
        body, media_type="text/html", headers=attachment(f"{download_stem(take)}.report.html")
    )


@router.get(
    "/runs/{run_id}/download/{kind}",
    response_class=FileResponse,
    responses={
        200: {
            "content": {
                "text/plain": {},
                "text/csv": {},
                "application/json": {},
                "application/octet-stream": {},
            }
        },
        **responses(401, 404, 409),
    },
)
def download(
    run_id: str, kind: Literal["bvh", "csv", "trc", "c3d", "report"], services: ServicesDep
) -> FileResponse:
    """A run's output: ``bvh`` (corrected), ``csv``/``trc`` (filtered keypoints), ``c3d`` (a
    marker take's swaps repaired and gaps filled, filled samples with residual 0),
    ``report``."""
    run = services.repository.require_done(run_id)
    path = RunFolder.of(services.files, run_id).download(kind)
    if not path.is_file():
        raise NotFoundError(f"Expected a {kind} output for run {run_id}, got none for this take")
    take = services.repository.get_take(str(run["take_id"]))
    return FileResponse(
        path, media_type=MEDIA_TYPES[kind], headers=attachment(f"{download_stem(take)}.{path.name}")
    )
