"""A finished run's files written: its report, its point arrays, its corrected take in each
format it has and the reviewer prior it used; and the summary the run stores.

The paths are :class:`~mocapqa.jobs.run_folder.RunFolder`'s; every file is written atomically
and the report last, so a folder with a report holds every file it lists. The analysis stack
is imported inside the writers: the batch client imports the run folder's names without it.
"""

from __future__ import annotations

import io
import json
import logging
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from mocapqa.errors import MocapQAError
from mocapqa.jobs.corrected_takes import (
    write_corrected_bvh,
    write_corrected_c3d,
    write_filtered_keypoints,
)
from mocapqa.jobs.run_folder import RunFolder
from mocapqa.store.files import FileStore

if TYPE_CHECKING:
    from mocapqa.pipeline.analyze import AnalysisResult
    from mocapqa.twist.reviewer_prior import ReviewerPrior

__all__ = ["run_summary", "write_outputs"]

log = logging.getLogger(__name__)


def run_summary(result: AnalysisResult) -> dict[str, Any]:
    """What a run stores as its summary: the report's summary, step states and QA summary."""
    from mocapqa.pipeline.summary import qa_summary

    return {
        **result.report["summary"],
        "steps": {k: v["state"] for k, v in result.report["steps"].items()},
        "qa": qa_summary(result),
    }


def _point_arrays(result: AnalysisResult) -> bytes:
    """The run's :data:`~mocapqa.jobs.run_folder.POINTS_NPZ` bytes."""
    arrays: dict[str, Any] = {
        "raw": result.raw_points.astype(np.float32),
        "corrected": result.corrected_points.astype(np.float32),
    }
    if result.raw_rotations is not None and result.corrected_rotations is not None:
        # Half precision (about 1e-3 per component) is finer than a drawn bone can show.
        arrays["raw_rotations"] = result.raw_rotations.astype(np.float16)
        arrays["corrected_rotations"] = result.corrected_rotations.astype(np.float16)
    if result.confidence is not None:
        arrays["confidence"] = result.confidence.astype(np.float16)
    if result.bridged is not None:
        arrays["bridged"] = result.bridged
    if result.markers is not None:
        arrays["filled"] = result.markers.filled
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


def _write_filtered(run: RunFolder, run_id: str, result: AnalysisResult) -> list[str]:
    """The filtered keypoints as CSV (with its sidecar) and TRC; returns the kinds written."""
    if result.filtered_keypoints is None:
        return []
    kinds = []
    for kind in ("csv", "trc"):
        try:
            write_filtered_keypoints(run.download(kind), result.filtered_keypoints, run_id)
            kinds.append(kind)
        except MocapQAError as e:
            log.info("no %s output for run %s: %s", kind, run_id, e)
    return kinds


def _report_json(
    result: AnalysisResult, kinds: list[str], prior: ReviewerPrior | None = None
) -> bytes:
    """The report as stored: with its downloads, for keypoints the bones to draw and, for a
    run with a reviewer prior, the prior's ``summary`` (hash and counts) as
    ``reviewer_prior``."""
    from mocapqa.render.layouts import bones_for_keypoints

    points = result.report["points"]
    if result.report["kind"] == "keypoints":
        # The 3D views join the keypoints of a known layout (BODY_25B, MediaPipe 33, Pose2Sim);
        # markers of no known layout by the sticks of their inferred segments, when checked.
        layout = bones_for_keypoints(tuple(points["names"])).tolist()
        if layout or "bones" not in points:
            points = {**points, "bones": layout}
    report = {**result.report, "points": points, "downloads": kinds}
    if prior is not None:
        report["reviewer_prior"] = prior.summary()
    return json.dumps(report, allow_nan=False).encode()


def write_outputs(
    files: FileStore,
    run_id: str,
    result: AnalysisResult,
    source: Path | None = None,
    prior: ReviewerPrior | None = None,
) -> list[str]:
    """Write a run's files (report, points, corrected BVH or filtered keypoints; for a C3D
    marker take, ``corrected.c3d``: :func:`~mocapqa.jobs.corrected_takes.write_corrected_c3d`;
    the reviewer ``prior`` the run used, :data:`~mocapqa.jobs.run_folder.PRIOR_JSON`), the
    report last.

    Parameters
    ----------
    files : FileStore
    run_id : str
    result : AnalysisResult
    source : Path, optional
        The take's stored file (a C3D's is opened again for its residuals and other groups).
    prior : ReviewerPrior, optional
        The reviewer prior the analysis used (written whole, and summarised in the report).

    Returns
    -------
    list of str
        The download kinds written (``"report"``, ``"bvh"``, ``"csv"``, ``"trc"``, ``"c3d"``).
    """
    run = RunFolder.of(files, run_id)
    kinds = ["report"]
    files.write_bytes(run.points, _point_arrays(result))
    if result.corrected_motion is not None:
        write_corrected_bvh(files, run.download("bvh"), result.corrected_motion)
        kinds.append("bvh")
    kinds += _write_filtered(run, run_id, result)
    if result.markers is not None and source is not None and source.suffix.lower() == ".c3d":
        try:
            write_corrected_c3d(run.download("c3d"), source, result.markers)
            kinds.append("c3d")
        except MocapQAError as e:
            log.info("no c3d output for run %s: %s", run_id, e)
    if prior is not None:
        files.write_bytes(run.prior, json.dumps(prior.to_json(), indent=2).encode())
    files.write_bytes(run.report, _report_json(result, kinds, prior))
    return kinds
