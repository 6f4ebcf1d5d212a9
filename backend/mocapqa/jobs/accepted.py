"""A run's twist intervals with reviewers' decisions, and the take with the accepted ones.

The decided take is the raw take with exactly the levels of the accepted intervals removed
(:func:`mocapqa.twist.levels.remove_levels`): an interval's newest decision wins; an interval
with none follows the run's own ``twist_apply`` choice (its ``applied`` flag). No motion filter
is applied, whatever the run's options.
"""

from __future__ import annotations

import functools
import json
from typing import Any

from mocapqa.core.motion import Motion
from mocapqa.errors import ConflictError, NotFoundError
from mocapqa.io.bvh_write import format_bvh
from mocapqa.jobs.intake import reading_of
from mocapqa.pipeline.loading import ReadLimits, ReadOptions, read_take_file
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.files import FileStore
from mocapqa.twist.levels import remove_levels

__all__ = ["decided_bvh", "decided_motion", "run_intervals", "with_decisions"]


def run_intervals(files: FileStore, run_id: str) -> list[dict[str, Any]]:
    """The twist intervals of a finished run (``id``, ``joint``, ``confidence``, ``applied``,
    ``levels``, …) from its report.

    Raises
    ------
    ConflictError
        For a keypoint take or a run without the twist check.
    """
    path = files.existing(files.run_dir(run_id) / "report.json", "the report")
    stat = path.stat()
    kind, intervals = _report_intervals(str(path), stat.st_mtime_ns, stat.st_size)
    if kind != "motion":
        raise ConflictError(
            f"Expected a run of a motion (BVH) take, got run {run_id} of a keypoint take: "
            "keypoint takes have no twist intervals to accept or reject"
        )
    if intervals is None:
        raise ConflictError(
            f"Expected a run with the twist check, got run {run_id} without it: start a run "
            "with 'twist' in checks"
        )
    return [dict(interval) for interval in intervals]


@functools.lru_cache(maxsize=64)
def _report_intervals(
    path: str, mtime_ns: int, size: int
) -> tuple[str | None, tuple[dict[str, Any], ...] | None]:
    """A report's take kind and twist intervals (None without the twist check), read once
    per version of the file (its path, change time and size): a finished run's report is
    written once, and parsing it (a few MB) was most of the cost of a decisions request."""
    del mtime_ns, size  # the cache key only
    with open(path, "rb") as handle:
        report = json.loads(handle.read())
    twist = (report.get("series") or {}).get("twist")
    return report.get("kind"), None if twist is None else tuple(twist["intervals"])


def with_decisions(intervals: list[dict[str, Any]], latest: dict[int, str]) -> list[dict[str, Any]]:
    """Each interval with its newest ``decision`` (None without one) and ``corrected``: whether
    the decided take removes it (accepted, or undecided and applied by the run)."""
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
    path = files.take_dir(str(take["id"])) / str(take["file_name"])
    if not path.is_file():
        raise NotFoundError(f"Expected the file of take {take['id']}, got none")
    reading = reading_of(files, str(take["id"])) or {}
    options = ReadOptions.from_json(reading.get("read_options"))
    raw = read_take_file(path, str(take["format"]), str(take["name"]), options, limits)
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


def decided_bvh(motion: Motion) -> bytes:
    """The decided take as BVH text (the writer the run's own downloads use)."""
    return format_bvh(motion).encode()
