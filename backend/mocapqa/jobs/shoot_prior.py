"""The reviewer prior of a take's run: its shoot's other takes' decisions, read from the store.

A run of a take in a shoot uses the labels of the shoot's *other* takes (the take's own
decisions are applied by its decided download already, :mod:`mocapqa.jobs.accepted`): the
newest decision of each twist interval of each take's decided run of the robust twist method
(:meth:`mocapqa.store.decisions.IntervalDecisions.shoot_labels`; a run of the paper's method
scores no calibrated probability, so its decisions are no labels), each interval's joint and
calibrated probability read from that run's report findings, its rig family from the take's
QA row. A take whose review status is ``approved`` gets no prior: a decision never changes an
approved take. The prior is data from here on (:class:`mocapqa.twist.reviewer_prior.ReviewerPrior`):
the run records it (:data:`mocapqa.jobs.run_folder.PRIOR_JSON`) and the analysis takes it as an
argument.
"""

from __future__ import annotations

from typing import Any

from mocapqa.jobs.twist_items import twist_items_of
from mocapqa.store.decisions import APPROVED, IntervalDecisions
from mocapqa.store.files import FileStore
from mocapqa.twist.reviewer_prior import ReviewerPrior

__all__ = ["APPROVED", "shoot_prior"]


def shoot_prior(
    decisions: IntervalDecisions, files: FileStore, take: dict[str, Any]
) -> ReviewerPrior | None:
    """The prior a new run of ``take`` (its row, with ``shoot_id`` and ``review_status``) uses.

    Returns
    -------
    ReviewerPrior or None
        None for a take outside a shoot, an approved take, or a shoot whose other takes have
        no decision on a twist interval.
    """
    shoot_id = take.get("shoot_id")
    if not shoot_id or take.get("review_status") == APPROVED:
        return None
    labels = [r for r in decisions.shoot_labels(str(shoot_id)) if r["take_id"] != take["id"]]
    items: dict[str, dict[int, tuple[str, float]]] = {}
    decided, runs = [], set()
    for label in labels:
        run_id = str(label["run_id"])
        if run_id not in items:
            items[run_id] = twist_items_of(files, run_id)
        item = items[run_id].get(int(label["interval_id"]))
        if item is not None:
            decided.append((str(label["rig"]), item[0], item[1], str(label["decision"])))
            runs.add(run_id)
    if not decided:
        return None
    return ReviewerPrior.from_decisions(str(shoot_id), decided, runs)
