"""A run's corrections with reviewers' decisions, and the take with the accepted ones.

A motion run's corrections are its twist intervals; a marker run's (the ``markers`` check of a
C3D or TRC take) its swaps. An item's newest decision wins; an item with none follows the run's
own choice (its ``applied`` flag: ``twist_apply`` for intervals, the confident rule for swaps).

* The decided motion is the raw take with exactly the levels of the intervals kept corrected
  removed (:func:`mocapqa.twist.levels.remove_levels`). No motion filter is applied, whatever
  the run's options.
* The decided marker take is the raw take with exactly the swaps kept corrected exchanged, then
  its gaps filled by the run's rule (the confident fills, chosen again on that take:
  :func:`mocapqa.pipeline.marker_step.decided_repair`), written as C3D like the run's
  ``corrected.c3d`` (:func:`mocapqa.jobs.run_folder.write_corrected_c3d`). No filter.

Neither touches the stored take, the run's own files or the take's review.
"""

from __future__ import annotations

import functools
import json
import tempfile
from pathlib import Path
from typing import Any

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ConflictError, NotFoundError
from mocapqa.io.bvh_write import format_bvh
from mocapqa.jobs.run_folder import RunFolder, read_options_of, write_corrected_c3d
from mocapqa.pipeline.loading import ReadLimits, read_take_file
from mocapqa.pipeline.marker_step import decided_repair
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.decisions import DecidedItem
from mocapqa.store.files import FileStore
from mocapqa.twist.levels import remove_levels

__all__ = [
    "decided_bvh",
    "decided_c3d",
    "decided_motion",
    "run_intervals",
    "run_items",
    "run_swaps",
    "with_decisions",
]

_SWAP_FIELDS = ("id", "markers", "start_frame", "end_frame", "confidence", "applied")
"""The fields of a ``swap`` finding a decision list shows."""


def run_items(files: FileStore, run_id: str) -> tuple[DecidedItem, list[dict[str, Any]]]:
    """What a finished run's decisions are on, and those items from its report: a motion
    run's twist intervals (``id``, ``joint``, ``confidence``, ``applied``, ``levels``, …) or a
    marker run's swaps (``id``, ``markers``, ``start_frame``, ``end_frame``, ``confidence``,
    ``applied``).

    Raises
    ------
    ConflictError
        For a run without the twist check (motion) or the markers check (keypoints).
    """
    path = files.existing(RunFolder.of(files, run_id).report, "the report")
    stat = path.stat()
    kind, intervals, swaps = _report_items(str(path), stat.st_mtime_ns, stat.st_size)
    if kind == "motion":
        if intervals is None:
            raise ConflictError(
                f"Expected a run with the twist check, got run {run_id} without it: start a "
                "run with 'twist' in checks"
            )
        return "interval", [dict(i) for i in intervals]
    if swaps is None:
        raise ConflictError(
            f"Expected a run of a motion (BVH) take or of a marker take with the markers check, "
            f"got run {run_id} of a keypoint take without it: keypoint takes have no twist "
            "intervals, and only the markers check (C3D and TRC takes) finds swaps"
        )
    return "swap", [dict(s) for s in swaps]


def _require(files: FileStore, run_id: str, item: DecidedItem) -> list[dict[str, Any]]:
    found, items = run_items(files, run_id)
    if found != item:
        have = "twist intervals" if found == "interval" else "swaps"
        take = "a motion take" if found == "interval" else "a keypoint take (markers)"
        raise ConflictError(
            f"Expected a run with {item}s to decide, got run {run_id} of {take}: its "
            f"decisions are on its {have}"
        )
    return items


def run_intervals(files: FileStore, run_id: str) -> list[dict[str, Any]]:
    """The twist intervals of a finished motion run (:func:`run_items`).

    Raises
    ------
    ConflictError
        For a keypoint take or a run without the twist check.
    """
    return _require(files, run_id, "interval")


def run_swaps(files: FileStore, run_id: str) -> list[dict[str, Any]]:
    """The swaps of a finished marker run (:func:`run_items`), ids as in its findings.

    Raises
    ------
    ConflictError
        For a motion take or a run without the markers check.
    """
    return _require(files, run_id, "swap")


@functools.lru_cache(maxsize=64)
def _report_items(
    path: str, mtime_ns: int, size: int
) -> tuple[str | None, tuple[dict[str, Any], ...] | None, tuple[dict[str, Any], ...] | None]:
    """A report's take kind, twist intervals (None without the twist check) and swaps (None
    without the markers check), read once per version of the file (its path, change time and
    size): a finished run's report is written once, and parsing it (a few MB) was most of the
    cost of a decisions request."""
    del mtime_ns, size  # the cache key only
    with open(path, "rb") as handle:
        report = json.loads(handle.read())
    twist = (report.get("series") or {}).get("twist")
    markers = (report.get("steps") or {}).get("markers") or {}
    swaps = (
        tuple(
            {k: f[k] for k in _SWAP_FIELDS}
            for f in report.get("findings") or []
            if f.get("kind") == "swap"
        )
        if markers.get("state") == "done"
        else None
    )
    return report.get("kind"), None if twist is None else tuple(twist["intervals"]), swaps


def with_decisions(intervals: list[dict[str, Any]], latest: dict[int, str]) -> list[dict[str, Any]]:
    """Each interval (or swap) with its newest ``decision`` (None without one) and
    ``corrected``: whether the decided take corrects it (accepted, or undecided and applied by
    the run)."""
    out = []
    for interval in intervals:
        decision = latest.get(int(interval["id"]))
        corrected = bool(interval["applied"]) if decision is None else decision == "accept"
        out.append({**interval, "decision": decision, "corrected": corrected})
    return out


def decided_motion(
    files: FileStore,
    run: dict[str, Any],
    take: dict[str, Any],
    latest: dict[int, str],
    limits: ReadLimits | None = None,
) -> Motion:
    """The raw take with the levels of the intervals the decisions keep corrected removed.

    Raises
    ------
    ConflictError
        For a keypoint take or a run without the twist check.
    NotFoundError
        When the take's file is gone.
    """
    intervals = with_decisions(run_intervals(files, str(run["id"])), latest)
    _, raw = _raw_take(files, take, limits)
    if not isinstance(raw, Motion):  # pragma: no cover - run_intervals refused keypoint runs
        raise ConflictError(f"Expected a motion take, got {take['format']}")
    levels: dict[str, list[tuple[int, int, float]]] = {}
    for interval in intervals:
        if interval["corrected"]:
            levels.setdefault(str(interval["joint"]), []).extend(
                (int(a), int(b), float(v)) for a, b, v in interval["levels"]
            )
    mapping = AnalysisOptions.from_json(run["options"]).mapping
    return remove_levels(raw, levels, mapping)


def _raw_take(
    files: FileStore, take: dict[str, Any], limits: ReadLimits | None
) -> tuple[Path, Motion | KeypointSequence]:
    """The take's stored file and the take read from it as the run read it."""
    path = files.take_dir(str(take["id"])) / str(take["file_name"])
    if not path.is_file():
        raise NotFoundError(f"Expected the file of take {take['id']}, got none")
    options = read_options_of(path.parent)
    return path, read_take_file(path, str(take["format"]), str(take["name"]), options, limits)


def decided_c3d(
    files: FileStore,
    run: dict[str, Any],
    take: dict[str, Any],
    latest: dict[int, str],
    limits: ReadLimits | None = None,
) -> bytes:
    """The C3D of a marker take with exactly the swaps the decisions keep corrected repaired,
    then its gaps filled by the run's rule, as the run's ``corrected.c3d`` is written.

    Raises
    ------
    ConflictError
        For a run without swaps to decide, a take that is not a C3D, or a take whose swaps
        are no longer the run's (found again by another version of the check).
    NotFoundError
        When the take's file is gone.
    """
    swaps = with_decisions(run_swaps(files, str(run["id"])), latest)
    if str(take["format"]) != "c3d":
        raise ConflictError(
            f"Expected a C3D take for the decided C3D, got a {take['format']} take: the "
            "decided download of a marker take is written as C3D only"
        )
    path, raw = _raw_take(files, take, limits)
    if not isinstance(raw, KeypointSequence):  # pragma: no cover - run_swaps refused others
        raise ConflictError(f"Expected a marker take, got {take['format']}")
    repair = decided_repair(raw, {int(s["id"]) for s in swaps if s["corrected"]})
    found = [(list(s.markers), s.start, s.end) for s in repair.swaps]
    listed = [(list(s["markers"]), s["start_frame"], s["end_frame"]) for s in swaps]
    if found != listed:
        raise ConflictError(
            f"Expected the swaps of run {run['id']} in its take, found others ({len(found)} "
            f"against {len(listed)}): start a new run of the take to decide on its swaps"
        )
    with tempfile.TemporaryDirectory(prefix="mocapqa-decided-") as folder:
        target = Path(folder) / "decided.c3d"
        write_corrected_c3d(target, path, repair)
        return target.read_bytes()


def decided_bvh(motion: Motion) -> bytes:
    """The decided take as BVH text (the writer the run's own downloads use)."""
    return format_bvh(motion).encode()
