"""A run's corrections with reviewers' decisions, and the motion take with the accepted ones.

A motion run's corrections are its twist intervals; a marker run's (the ``markers`` check of a
C3D or TRC take) its swaps. An item's newest decision wins; an item with none follows the run's
own choice (its ``applied`` flag: ``twist_apply`` for intervals, the confident rule for swaps).
Beside them, a run with the feet check has foot locks, one per skate finding
(:func:`run_locks`): a lock is kept when accepted, or undecided and locked by the run (its
``feet_apply`` choice; cleanup is off by default, so a default run's undecided locks are not),
and applied after the other corrections (:mod:`mocapqa.jobs.decided_feet`).

* The decided motion is the raw take with exactly the levels of the intervals kept corrected
  removed (:func:`mocapqa.twist.levels.remove_levels`), then its kept foot locks solved
  (leg joints only). No motion filter is applied, whatever the run's options. A motion run
  with the feet check but without the twist check has locks only.
* The decided marker take (C3D or TRC) is :mod:`mocapqa.jobs.decided_markers`'.

Neither touches the stored take, the run's own files or the take's review.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ConflictError, NotFoundError
from mocapqa.io.bvh_write import format_bvh
from mocapqa.jobs.decided_feet import kept_locks, lock_kept_motion
from mocapqa.jobs.reading_record import read_options_of
from mocapqa.jobs.run_folder import RunFolder
from mocapqa.pipeline.loading import ReadLimits, read_take_file
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.decisions import DecidedItem
from mocapqa.store.files import FileStore
from mocapqa.twist.levels import remove_levels

__all__ = [
    "ReportItems",
    "decided_bvh",
    "decided_motion",
    "run_decidables",
    "run_intervals",
    "run_items",
    "run_locks",
    "run_report_items",
    "run_swaps",
    "stored_take",
    "with_decisions",
]

_SWAP_FIELDS = ("id", "markers", "start_frame", "end_frame", "confidence", "applied")
"""The fields of a ``swap`` finding a decision list shows."""
_LOCK_FIELDS = (
    "id", "foot", "joint", "start_frame", "end_frame", "value", "unit", "confidence",
    "speed_cm_s", "applied",
)  # fmt: skip
"""The fields of a ``skate`` finding a decision list shows of its foot lock."""


class ReportItems(NamedTuple):
    """What a run's report holds to decide on (None for a check the run did not finish).

    Parameters
    ----------
    kind : str or None
        The take kind (``"motion"`` or ``"keypoints"``).
    intervals : tuple of dict or None
        The twist intervals, as the report's ``series.twist`` lists them.
    swaps : tuple of dict or None
        The ``swap`` findings' decision fields.
    locks : tuple of dict or None
        The ``skate`` findings' fields of their foot locks (those with an id).
    """

    kind: str | None
    intervals: tuple[dict[str, Any], ...] | None
    swaps: tuple[dict[str, Any], ...] | None
    locks: tuple[dict[str, Any], ...] | None


def run_report_items(files: FileStore, run_id: str) -> ReportItems:
    """What a finished run's report holds to decide on, read once per version of the file.

    Raises
    ------
    NotFoundError
        When the run has no report.
    """
    path = files.existing(RunFolder.of(files, run_id).report, "the report")
    try:
        stat = path.stat()
        return _report_items(str(path), stat.st_mtime_ns, stat.st_size)
    except FileNotFoundError as error:  # its take was deleted since the check above
        raise NotFoundError(f"Expected the report of run {run_id!r}, got none") from error


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
    kind, intervals, swaps, _ = run_report_items(files, run_id)
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
    if item == "swap" and run_report_items(files, run_id).kind == "motion":
        raise ConflictError(
            f"Expected a run of a marker take (C3D or TRC), got run {run_id} of a motion take: "
            "its reviewed take is GET /runs/{id}/decisions/bvh"
        )
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


def run_decidables(
    files: FileStore, run_id: str
) -> tuple[DecidedItem, list[dict[str, Any]], list[dict[str, Any]]]:
    """Everything a finished run's reviewers decide on: what its corrections are, those items
    (:func:`run_items`) and its foot locks (:func:`run_locks`, empty without the feet check).
    A run with foot locks but neither twist intervals nor swaps to decide has no corrections:
    ``"interval"`` (a motion take) or ``"swap"`` (a keypoint take) with no items.

    Raises
    ------
    ConflictError
        For a run with neither corrections (:func:`run_items`) nor foot locks to decide.
    """
    found = run_report_items(files, run_id)
    locks = [dict(lock) for lock in found.locks or ()]
    try:
        item, items = run_items(files, run_id)
    except ConflictError:
        if not locks:
            raise
        return ("interval" if found.kind == "motion" else "swap"), [], locks
    return item, items, locks


def run_locks(files: FileStore, run_id: str) -> list[dict[str, Any]] | None:
    """The foot locks of a finished run: its feet step's skate findings (``id`` as
    ``mocapqa feet fix --apply`` takes it, ``foot``, ``joint``, ``start_frame``,
    ``end_frame``, ``value``, ``unit``, ``confidence``, ``speed_cm_s``), or None for a run
    whose feet step did not run to the end."""
    locks = run_report_items(files, run_id).locks
    return None if locks is None else [dict(lock) for lock in locks]


@functools.lru_cache(maxsize=64)
def _report_items(path: str, mtime_ns: int, size: int) -> ReportItems:
    """A report's take kind, twist intervals (None without the twist check), swaps (None
    without the markers check) and foot locks (None without the feet check), read once per
    version of the file (its path, change time and size): a finished run's report is written
    once, and parsing it (a few MB) was most of the cost of a decisions request."""
    del mtime_ns, size  # the cache key only
    with open(path, "rb") as handle:
        report = json.loads(handle.read())
    twist = (report.get("series") or {}).get("twist")
    steps = report.get("steps") or {}
    findings = report.get("findings") or []

    def of_kind(step: str, kind: str, fields: tuple[str, ...]) -> tuple[dict[str, Any], ...] | None:
        if ((steps.get(step) or {}).get("state")) != "done":
            return None
        return tuple({k: f.get(k) for k in fields} for f in findings if f.get("kind") == kind)

    skates = of_kind("feet", "skate", _LOCK_FIELDS)
    return ReportItems(
        report.get("kind"),
        None if twist is None else tuple(twist["intervals"]),
        of_kind("markers", "swap", _SWAP_FIELDS),
        None if skates is None else tuple(s for s in skates if isinstance(s["id"], str)),
    )


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
    locks: Mapping[str, str] | None = None,
) -> Motion:
    """The raw take with the levels of the intervals the decisions keep corrected removed,
    then the kept foot locks solved.

    Parameters
    ----------
    files, run, take
        The run's files, the run's row and its take's row.
    latest : dict of int to str
        Twist interval id → its newest decision.
    limits : ReadLimits, optional
    locks : mapping of str to str, optional
        Foot lock id → its newest decision; the locks kept are applied
        (:func:`mocapqa.jobs.decided_feet.lock_kept`).

    Raises
    ------
    ConflictError
        For a keypoint take, a run with neither the twist nor the feet check, or kept
        locks the take's feet check no longer finds.
    NotFoundError
        When the take's file is gone.
    """
    run_id = str(run["id"])
    found = run_report_items(files, run_id)
    if found.kind == "motion" and found.intervals is None and found.locks is not None:
        listed: list[dict[str, Any]] = []  # the feet check without the twist check
    else:
        listed = run_intervals(files, run_id)
    intervals = with_decisions(listed, latest)
    _, raw = stored_take(files, take, limits)
    if not isinstance(raw, Motion):  # pragma: no cover - run_intervals refused keypoint runs
        raise ConflictError(f"Expected a motion take, got {take['format']}")
    levels: dict[str, list[tuple[int, int, float]]] = {}
    for interval in intervals:
        if interval["corrected"]:
            levels.setdefault(str(interval["joint"]), []).extend(
                (int(a), int(b), float(v)) for a, b, v in interval["levels"]
            )
    mapping = AnalysisOptions.from_json(run["options"]).mapping
    decided = remove_levels(raw, levels, mapping)
    kept = kept_locks(found.locks or (), locks or {})
    return lock_kept_motion(raw, decided, kept, mapping, run_id)


def stored_take(
    files: FileStore, take: dict[str, Any], limits: ReadLimits | None
) -> tuple[Path, Motion | KeypointSequence]:
    """The take's stored file and the take read from it as the run read it.

    Parameters
    ----------
    files : FileStore
    take : dict
        The take's row (``id``, ``file_name``, ``format``, ``name``).
    limits : ReadLimits, optional

    Raises
    ------
    NotFoundError
        When the take's file is gone.
    """
    path = files.take_dir(str(take["id"])) / str(take["file_name"])
    if not path.is_file():
        raise NotFoundError(f"Expected the file of take {take['id']}, got none")
    options = read_options_of(path.parent)
    return path, read_take_file(path, str(take["format"]), str(take["name"]), options, limits)


def decided_bvh(motion: Motion) -> bytes:
    """The decided take as BVH text (the writer the run's own downloads use)."""
    return format_bvh(motion).encode()
