"""A run's corrections with reviewers' decisions, and the take with the accepted ones.

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
* The decided marker take is the raw take with exactly the swaps kept corrected exchanged, then
  its gaps filled by the run's rule (the confident fills, chosen again on that take:
  :func:`mocapqa.pipeline.marker_step.decided_repair`), then its kept foot locks pinned,
  written as C3D like the run's ``corrected.c3d``
  (:func:`mocapqa.jobs.corrected_takes.write_corrected_c3d`), or as TRC (a TRC take's, or a C3D
  take's for OpenSim: :func:`decided_trc`). No filter. A marker run with the feet check but
  without the markers check has locks only: its decided take is the raw take (no swap
  exchanged, no gap filled) with its kept foot locks pinned.

Neither touches the stored take, the run's own files or the take's review.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ConflictError, NotFoundError
from mocapqa.io.bvh_write import format_bvh
from mocapqa.io.trc import format_trc
from mocapqa.jobs.corrected_takes import write_corrected_c3d
from mocapqa.jobs.decided_feet import kept_locks, lock_kept_markers, lock_kept_motion
from mocapqa.jobs.reading_record import read_options_of
from mocapqa.jobs.run_folder import RunFolder
from mocapqa.markers.fill import FillResult
from mocapqa.markers.repair import MarkerRepair
from mocapqa.markers.swaps import repair_swaps
from mocapqa.pipeline.loading import ReadLimits, read_take_file
from mocapqa.pipeline.marker_step import decided_repair
from mocapqa.pipeline.options import MARKER_FORMATS, AnalysisOptions
from mocapqa.store.decisions import DecidedItem
from mocapqa.store.files import FileStore
from mocapqa.twist.levels import remove_levels

__all__ = [
    "decided_bvh",
    "decided_c3d",
    "decided_motion",
    "decided_trc",
    "run_decidables",
    "run_intervals",
    "run_items",
    "run_locks",
    "run_swaps",
    "with_decisions",
]

_SWAP_FIELDS = ("id", "markers", "start_frame", "end_frame", "confidence", "applied")
"""The fields of a ``swap`` finding a decision list shows."""
_LOCK_FIELDS = (
    "id", "foot", "joint", "start_frame", "end_frame", "value", "unit", "confidence",
    "speed_cm_s", "applied",
)  # fmt: skip
"""The fields of a ``skate`` finding a decision list shows of its foot lock."""


class _ReportItems(NamedTuple):
    """What a run's report holds to decide on (None for a check the run did not finish)."""

    kind: str | None
    intervals: tuple[dict[str, Any], ...] | None
    swaps: tuple[dict[str, Any], ...] | None
    locks: tuple[dict[str, Any], ...] | None


def _items_of(files: FileStore, run_id: str) -> _ReportItems:
    path = files.existing(RunFolder.of(files, run_id).report, "the report")
    stat = path.stat()
    return _report_items(str(path), stat.st_mtime_ns, stat.st_size)


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
    kind, intervals, swaps, _ = _items_of(files, run_id)
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
    if item == "swap" and _items_of(files, run_id).kind == "motion":
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
    found = _items_of(files, run_id)
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
    locks = _items_of(files, run_id).locks
    return None if locks is None else [dict(lock) for lock in locks]


@functools.lru_cache(maxsize=64)
def _report_items(path: str, mtime_ns: int, size: int) -> _ReportItems:
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
    return _ReportItems(
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
    found = _items_of(files, run_id)
    if found.kind == "motion" and found.intervals is None and found.locks is not None:
        listed: list[dict[str, Any]] = []  # the feet check without the twist check
    else:
        listed = run_intervals(files, run_id)
    intervals = with_decisions(listed, latest)
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
    decided = remove_levels(raw, levels, mapping)
    kept = kept_locks(found.locks or (), locks or {})
    return lock_kept_motion(raw, decided, kept, mapping, run_id)


def _raw_take(
    files: FileStore, take: dict[str, Any], limits: ReadLimits | None
) -> tuple[Path, Motion | KeypointSequence]:
    """The take's stored file and the take read from it as the run read it."""
    path = files.take_dir(str(take["id"])) / str(take["file_name"])
    if not path.is_file():
        raise NotFoundError(f"Expected the file of take {take['id']}, got none")
    options = read_options_of(path.parent)
    return path, read_take_file(path, str(take["format"]), str(take["name"]), options, limits)


def _marker_swaps(
    files: FileStore, run_id: str, take: dict[str, Any]
) -> list[dict[str, Any]] | None:
    """A marker run's swaps (:func:`run_swaps`), or None for a marker take's (C3D or TRC) run
    with the feet check but without the markers check: foot locks only."""
    found = _items_of(files, run_id)
    markers = str(take["format"]) in MARKER_FORMATS and found.kind != "motion"
    if markers and found.swaps is None and found.locks is not None:
        return None
    return run_swaps(files, run_id)


def _as_read(raw: KeypointSequence) -> MarkerRepair:
    """A marker take's "repair" that changes nothing: no swap exchanged, no gap filled."""
    positions = np.array(raw.positions, dtype=np.float64)
    nothing = np.zeros(positions.shape[:2], dtype=bool)
    residuals = np.where(raw.missing, -1.0, 1.0)
    return MarkerRepair(positions, residuals, (), (), FillResult(positions, nothing, ()))


def _decided_markers(
    files: FileStore,
    run: dict[str, Any],
    take: dict[str, Any],
    latest: dict[int, str],
    limits: ReadLimits | None,
    locks: Mapping[str, str] | None,
) -> tuple[Path, KeypointSequence, MarkerRepair]:
    """The stored file of a marker take, the take as the run read it, and its repair with
    exactly the swaps the decisions keep corrected, its gaps filled by the run's rule and its
    kept foot locks pinned (:func:`decided_c3d`); a run without the markers check
    (:func:`_marker_swaps`) has the take as read with its kept foot locks pinned."""
    run_id = str(run["id"])
    listed = _marker_swaps(files, run_id, take)
    path, raw = _raw_take(files, take, limits)
    if not isinstance(raw, KeypointSequence):  # pragma: no cover - run_swaps refused others
        raise ConflictError(f"Expected a marker take, got {take['format']}")
    if listed is None:
        return path, raw, _pinned(raw, _as_read(raw), files, run_id, locks)
    swaps = with_decisions(listed, latest)
    repair = decided_repair(raw, {int(s["id"]) for s in swaps if s["corrected"]})
    found = [(list(s.markers), s.start, s.end) for s in repair.swaps]
    wanted = [(list(s["markers"]), s["start_frame"], s["end_frame"]) for s in swaps]
    if found != wanted:
        raise ConflictError(
            f"Expected the swaps of run {run['id']} in its take, found others ({len(found)} "
            f"against {len(wanted)}): start a new run of the take to decide on its swaps"
        )
    return path, raw, _pinned(raw, repair, files, run_id, locks)


def _pinned(
    raw: KeypointSequence,
    repair: MarkerRepair,
    files: FileStore,
    run_id: str,
    locks: Mapping[str, str] | None,
) -> MarkerRepair:
    """``repair`` with the run's kept foot locks (``locks``: id → newest decision)
    pinned on its positions."""
    kept = kept_locks(_items_of(files, run_id).locks or (), locks or {})
    if not kept:
        return repair
    pinned = lock_kept_markers(raw, repair.positions, kept, run_id)
    return dataclasses.replace(repair, positions=pinned)


def decided_c3d(
    files: FileStore,
    run: dict[str, Any],
    take: dict[str, Any],
    latest: dict[int, str],
    limits: ReadLimits | None = None,
    locks: Mapping[str, str] | None = None,
) -> bytes:
    """The C3D of a marker take with exactly the swaps the decisions keep corrected repaired,
    then its gaps filled by the run's rule, as the run's ``corrected.c3d`` is written, then
    its kept foot locks pinned (``locks``: lock id → its newest decision). A run of the
    feet check without the markers check gives the raw take with its kept locks pinned.

    Raises
    ------
    ConflictError
        For a run with neither swaps nor foot locks to decide, a take that is not a C3D, or a
        take whose swaps are no longer the run's (found again by another version of the check).
    NotFoundError
        When the take's file is gone.
    """
    _marker_swaps(files, str(run["id"]), take)
    if str(take["format"]) != "c3d":
        raise ConflictError(
            f"Expected a C3D take for the decided C3D, got a {take['format']} take: the "
            f"decided download of a {take['format']} marker take is /decisions/trc"
        )
    path, _, repair = _decided_markers(files, run, take, latest, limits, locks)
    with tempfile.TemporaryDirectory(prefix="mocapqa-decided-") as folder:
        target = Path(folder) / "decided.c3d"
        write_corrected_c3d(target, path, repair)
        return target.read_bytes()


def decided_trc(
    files: FileStore,
    run: dict[str, Any],
    take: dict[str, Any],
    latest: dict[int, str],
    limits: ReadLimits | None = None,
    locks: Mapping[str, str] | None = None,
) -> bytes:
    """The TRC of a marker take (a TRC or a C3D take) decided as :func:`decided_c3d` decides
    it: exactly the swaps the decisions keep corrected repaired, its gaps filled by the run's
    rule, its kept foot locks pinned; written by :func:`mocapqa.io.trc.format_trc` with the
    take's rate, unit, marker names, frame numbers and times as the run read them (a run of the
    feet check without the markers check: the raw take with its kept locks pinned). TRC has no
    residual: a filled sample is a value like any other (the run's ``gap`` findings list the
    filled gaps) and a sample still missing is ``NaN``.

    Raises
    ------
    ConflictError
        For a take that is not a marker take (C3D or TRC), a run with neither the markers nor
        the feet check, or a take whose swaps are no longer the run's.
    NotFoundError
        When the take's file is gone.
    """
    if str(take["format"]) not in MARKER_FORMATS:
        kind = "motion" if str(take["format"]) == "bvh" else "keypoint"
        raise ConflictError(
            f"Expected a marker take ({', '.join(f.upper() for f in MARKER_FORMATS)}) for the "
            f"decided TRC, got a {kind} take ({take['format']}): "
            + (
                "a motion take's decided download is /decisions/bvh"
                if kind == "motion"
                else "only marker takes have swaps and fills to decide"
            )
        )
    _, raw, repair = _decided_markers(files, run, take, latest, limits, locks)
    exchanged = repair_swaps(raw.confidence, repair.repaired)
    decided = dataclasses.replace(
        raw, positions=repair.positions, confidence=np.where(repair.filled, 1.0, exchanged)
    )
    name = str(take.get("name") or take["file_name"])
    stem = name.rsplit(".", 1)[0] if "." in name else name
    return format_trc(decided, f"{stem}.decided.trc").encode()


def decided_bvh(motion: Motion) -> bytes:
    """The decided take as BVH text (the writer the run's own downloads use)."""
    return format_bvh(motion).encode()
