"""Rendered run outputs: the take-list thumbnail (PNG) and the HTML QA report.

Conventions
-----------
Everything is drawn through the app's one :class:`~mocapqa.render.service.RenderService`
(VTK must render on a single thread). The thumbnail is made by the job after the analysis and
stored beside the run's other files as ``thumbnail.png``; where rendering is unavailable
(:class:`~mocapqa.errors.RenderUnavailableError`) no PNG is written and the take list keeps the
SVG drawn by :mod:`mocapqa.jobs.thumbnails`. The HTML report is built on first download from the
stored ``report.json`` and ``points.npz`` (so it shows exactly that run) and kept as
``report.html``; without rendering it says why the contact sheet is missing.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError, MocapQAError
from mocapqa.jobs.run_folder import REPORT_HTML, THUMBNAIL_PNG, RunFolder
from mocapqa.jobs.stored_run import StoredRun, read_run
from mocapqa.render.scene import SkeletonTrack, track_from_points
from mocapqa.render.service import RenderService
from mocapqa.render.sheet import tiles_from_intervals
from mocapqa.report.findings import sheet_findings
from mocapqa.report.html import report_from_analysis
from mocapqa.store.files import FileStore

__all__ = [
    "MAX_SHEET_TILES",
    "REPORT_HTML",
    "THUMBNAIL_PNG",
    "html_report",
    "render_thumbnail",
    "run_tracks",
    "tracks_of",
]

MAX_SHEET_TILES = 8
"""Contact-sheet tiles in the HTML report: twist intervals first, then the worst limits."""

log = logging.getLogger(__name__)


def _track(
    report: Mapping[str, Any], positions: FloatArray, up_axis: str | None = None
) -> SkeletonTrack:
    points = report["points"]
    fps = float(report["summary"]["fps"])
    return track_from_points(points["names"], points["parents"], positions, fps, up_axis)


def tracks_of(
    report: Mapping[str, Any], raw: FloatArray, corrected: FloatArray
) -> tuple[SkeletonTrack, SkeletonTrack]:
    """A run's raw and corrected positions, shape (F, P, 3), as tracks to draw, named and
    joined as its report's ``points`` say, at its ``summary.fps`` (the corrected track in
    the raw one's up axis).

    Raises
    ------
    KeyError
        When the report lacks the points' names or parents, or the frame rate.
    """
    raw_track = _track(report, raw)
    return raw_track, _track(report, corrected, raw_track.up_axis)


def run_tracks(run: StoredRun) -> tuple[SkeletonTrack, SkeletonTrack]:
    """A stored run's raw and corrected tracks (:func:`tracks_of`).

    Raises
    ------
    InputError
        When its report does not describe its points.
    """
    try:
        return tracks_of(run.report, run.raw, run.corrected)
    except (KeyError, ValueError, TypeError) as e:
        raise InputError(f"{run.folder}: Expected a readable run report and points, got {e}") from e


def render_thumbnail(
    files: FileStore,
    run_id: str,
    report: Mapping[str, Any],
    raw_points: FloatArray,
    renderer: RenderService,
) -> bool:
    """Render the run's middle frame and store it as ``thumbnail.png``.

    Parameters
    ----------
    files : FileStore
        Where the run's files live.
    run_id : str
        The run.
    report : mapping
        The run's report (its ``points`` and ``summary.fps`` are used).
    raw_points : ndarray, shape (F, P, 3)
        The drawn points, file units, NaN where missing.
    renderer : RenderService
        The app's render thread.

    Returns
    -------
    bool
        Whether a PNG was written (False when rendering is unavailable or the take cannot be
        drawn; the SVG thumbnail is used then).
    """
    try:
        png = renderer.thumbnail(_track(report, np.asarray(raw_points, dtype=np.float64)))
    except MocapQAError as e:
        log.info("no rendered thumbnail for run %s: %s", run_id, e)
        return False
    files.write_bytes(RunFolder.of(files, run_id).thumbnail, png)
    return True


def _sheet_tiles(
    analysis: Mapping[str, Any], raw: SkeletonTrack, corrected: SkeletonTrack
) -> list[Any]:
    chosen = sheet_findings(list(analysis.get("findings", [])), MAX_SHEET_TILES)
    return tiles_from_intervals(chosen, raw, corrected)


def html_report(
    files: FileStore, run_id: str, take: Mapping[str, Any], renderer: RenderService | None
) -> bytes:
    """The run's self-contained HTML report, built once and then read from ``report.html``.

    Parameters
    ----------
    files : FileStore
        Where the run's files live.
    run_id : str
        A finished run.
    take : mapping
        The take's row (name, file name, format, sha256).
    renderer : RenderService or None
        Draws the contact sheet; None (or unavailable rendering) leaves it out with the reason.

    Raises
    ------
    NotFoundError
        If the run's files are missing.
    InputError
        If they cannot be read.
    """
    folder = RunFolder.of(files, run_id)
    cached = folder.report_html
    if cached.is_file():
        return cached.read_bytes()
    files.existing(folder.report, "the report")
    files.existing(folder.points, "the points")
    stored = read_run(folder.path)
    analysis = stored.report
    raw, corrected = run_tracks(stored)
    unavailable: dict[str, str] = {}
    sheet: bytes | None = None
    tiles = _sheet_tiles(analysis, raw, corrected)
    if tiles and renderer is None:
        unavailable["contact_sheet"] = "rendering unavailable: no render service"
    elif tiles and renderer is not None:
        try:
            sheet = renderer.contact_sheet(raw, tiles, corrected)
        except MocapQAError as e:
            unavailable["contact_sheet"] = f"rendering unavailable: {e}"
    facts = {
        "name": take.get("name"),
        "file": take.get("file_name"),
        "format": take.get("format"),
        "sha256": take.get("sha256"),
        "run": run_id,
    }
    settings = {
        "options": analysis.get("options", {}),
        "analysis_version": analysis.get("version"),
        "up_axis": raw.up_axis,
    }
    html = report_from_analysis(
        analysis, facts, contact_sheet_png=sheet, settings=settings, unavailable=unavailable
    ).encode("utf-8")
    if not unavailable:
        files.write_bytes(cached, html)
    return html
