"""The foot locks a run's decided take keeps (accepted, or undecided and locked by the run),
applied to it.

A run's foot locks are its feet step's skate findings (``id`` ``skate-left-120``, as
``mocapqa feet fix --apply`` takes them). A lock is applied when its newest decision is
``accept``, or when it has none and the run locked it (its ``applied`` flag, the run's
``feet_apply`` choice: ``"none"`` by default, cleanup is off); a rejected lock, and an
undecided one the run did not lock, leave the foot as recorded.

The locks are chosen and applied by the code of ``mocapqa feet fix --apply ID,ID``
(:func:`mocapqa.feet.fix.fix_feet`): the feet check runs again on the take as the run read it
(:func:`mocapqa.pipeline.feet.check_take_feet`, the check of the run's feet step, so the ids
are the run's), each kept skate finding gives its foot contact
(:func:`mocapqa.feet.fix_choice.choose_locks`), and

* a BVH take's decided motion (its accepted twist intervals removed) has those contacts
  locked by the two-bone leg IK of :func:`mocapqa.feet.fix.lock_feet`: only the hips', knees'
  and ankles' local rotations change, on the contacts and their blends;
* a C3D marker take's decided markers (its accepted swaps repaired, its gaps filled) have the
  markers of each foot pinned by :func:`mocapqa.feet.pin.pin_feet`: the heel, toe, ankle and
  other foot markers (:func:`mocapqa.feet.pin.marker_foot_members`) move horizontally together.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

from mocapqa.core.arrays import FloatArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import ConflictError
from mocapqa.feet.check import FeetReport
from mocapqa.feet.fix import fix_feet
from mocapqa.feet.fix_choice import finding_id
from mocapqa.feet.pin import FOOT_MARKER_ROLES, marker_foot_members
from mocapqa.pipeline.feet import check_take_feet, feet_params_of

__all__ = [
    "FOOT_MARKER_ROLES",
    "kept_locks",
    "lock_kept",
    "lock_kept_markers",
    "lock_kept_motion",
    "marker_foot_members",
]


def lock_kept(lock: Mapping[str, Any], decision: str | None) -> bool:
    """Whether the decided take locks ``lock`` (a skate finding of the run, with its ``applied``
    flag; a run recorded before the flag has none, and locked nothing): accepted, or undecided
    and locked by the run."""
    return bool(lock.get("applied")) if decision is None else decision == "accept"


def kept_locks(locks: Sequence[Mapping[str, Any]], latest: Mapping[str, str]) -> list[str]:
    """The ids of the locks the decided take locks (:func:`lock_kept`), in the order of
    ``locks``.

    Parameters
    ----------
    locks : sequence of mapping
        The run's foot locks (its skate findings), each with its ``id`` and ``applied``.
    latest : mapping of str to str
        Lock id → its newest decision (``"accept"`` or ``"reject"``); an id without one is
        undecided, and follows the run.
    """
    return [str(lock["id"]) for lock in locks if lock_kept(lock, latest.get(str(lock["id"])))]


def _check_found(report: FeetReport, skipped: int, ids: Sequence[str], run_id: str) -> None:
    """Raise unless the check of the take still finds every kept skate finding ``ids``.

    Raises
    ------
    ConflictError
        If the check of the take no longer finds one of them.
    """
    found = {finding_id(f, skipped) for f in report.findings if f.kind == "skate"}
    gone = [i for i in ids if i not in found]
    if gone:
        raise ConflictError(
            f"Expected the skate findings of run {run_id} in its take, got none for "
            f"{', '.join(gone)}: start a new run of the take to decide on its foot locks"
        )


def lock_kept_motion(
    raw: Motion,
    decided: Motion,
    ids: Sequence[str],
    mapping: Mapping[str, str] | None,
    run_id: str,
) -> Motion:
    """Lock the feet of a decided BVH take during the contacts of the kept skate findings.

    Parameters
    ----------
    raw : Motion
        The take as the run read it (its feet step checked this one).
    decided : Motion
        The same take with the reviewers' other corrections (twist intervals); the locks are
        solved on it.
    ids : sequence of str
        Skate finding ids kept (:func:`kept_locks`); none returns ``decided`` itself.
    mapping : mapping, optional
        The run's role mapping.
    run_id : str
        For messages.

    Returns
    -------
    Motion
        ``decided`` with only its leg joints' rotations changed, on the locked contacts and
        their blends.

    Raises
    ------
    ConflictError
        If the take's check no longer finds a kept finding.
    """
    if not ids:
        return decided
    roles = dict(mapping) if mapping else None
    params = feet_params_of(raw)
    points, report, skipped = check_take_feet(raw, roles, params)
    _check_found(report, skipped, ids, run_id)
    fixed = fix_feet(raw, points, report, skipped, ",".join(ids), params, decided, roles)
    return fixed.take if isinstance(fixed.take, Motion) else decided


def lock_kept_markers(
    raw: KeypointSequence, positions: FloatArray, ids: Sequence[str], run_id: str
) -> FloatArray:
    """Pin the feet of a decided marker take (C3D or TRC) during the contacts of the kept skate
    findings.

    Parameters
    ----------
    raw : KeypointSequence
        The take as the run read it (its feet step checked this one).
    positions : ndarray, shape (F, M, 3)
        The decided markers (swaps repaired, gaps filled), take units, NaN where missing.
    ids : sequence of str
        Accepted skate finding ids; none returns ``positions`` itself.
    run_id : str
        For messages.

    Returns
    -------
    ndarray, shape (F, M, 3)
        Only the foot markers (:func:`mocapqa.feet.pin.marker_foot_members`) move,
        horizontally, on the locked contacts and their blends.

    Raises
    ------
    ConflictError
        If the take's check no longer finds a kept finding.
    """
    if not ids:
        return positions
    params = feet_params_of(raw)
    points, report, skipped = check_take_feet(raw, None, params)
    _check_found(report, skipped, ids, run_id)
    decided = dataclasses.replace(raw, positions=positions)
    fixed = fix_feet(raw, points, report, skipped, ",".join(ids), params, decided)
    return fixed.take.positions if isinstance(fixed.take, KeypointSequence) else positions
