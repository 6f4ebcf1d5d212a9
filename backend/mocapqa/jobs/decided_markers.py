"""The decided marker take of a run: the raw take with the swaps reviewers keep corrected
exchanged, its gaps filled and its kept foot locks pinned, as C3D or TRC.

The decided marker take is the raw take with exactly the swaps kept corrected exchanged (an
item's newest decision wins; an item with none follows the run's confident rule, its
``applied`` flag: :func:`mocapqa.jobs.accepted.with_decisions`), then its gaps filled by the
run's rule (the confident fills, chosen again on that take:
:func:`mocapqa.pipeline.marker_step.decided_repair`), then its kept foot locks pinned
(:mod:`mocapqa.jobs.decided_feet`), written as C3D like the run's ``corrected.c3d``
(:func:`mocapqa.jobs.corrected_takes.write_corrected_c3d`), or as TRC (a TRC take's, or a C3D
take's for OpenSim: :func:`decided_trc`). No filter. A marker run with the feet check but
without the markers check has locks only: its decided take is the raw take (no swap exchanged,
no gap filled) with its kept foot locks pinned.

It touches neither the stored take, the run's own files nor the take's review.
"""

from __future__ import annotations

import dataclasses
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ConflictError
from mocapqa.io.trc import format_trc
from mocapqa.jobs.accepted import run_report_items, run_swaps, stored_take, with_decisions
from mocapqa.jobs.corrected_takes import write_corrected_c3d
from mocapqa.jobs.decided_feet import kept_locks, lock_kept_markers
from mocapqa.markers.fill import FillResult
from mocapqa.markers.repair import MarkerRepair
from mocapqa.markers.swap_repair import repair_swaps
from mocapqa.pipeline.loading import ReadLimits
from mocapqa.pipeline.marker_step import decided_repair
from mocapqa.pipeline.options import MARKER_FORMATS
from mocapqa.store.files import FileStore

__all__ = ["decided_c3d", "decided_trc"]


def _marker_swaps(
    files: FileStore, run_id: str, take: dict[str, Any]
) -> list[dict[str, Any]] | None:
    """A marker run's swaps (:func:`run_swaps`), or None for a marker take's (C3D or TRC) run
    with the feet check but without the markers check: foot locks only."""
    found = run_report_items(files, run_id)
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
    path, raw = stored_take(files, take, limits)
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
    kept = kept_locks(run_report_items(files, run_id).locks or (), locks or {})
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
