"""Request and response models of the decisions on twist intervals, swaps and foot locks
(``routes/decisions.py``)."""

from __future__ import annotations

from datetime import datetime
from typing import Literal

from pydantic import BaseModel, Field

from mocapqa.api.request_model import RequestModel
from mocapqa.store.decisions import DecidedItem, Decision

__all__ = [
    "DecisionIn",
    "DecisionOut",
    "DecisionsOut",
    "IntervalOut",
    "LockDecisionOut",
    "LockOut",
    "SwapOut",
]


class DecisionIn(RequestModel):
    """A reviewer's decision on one twist interval, swap or foot lock."""

    decision: Decision
    note: str = Field("", max_length=10_000)
    reviewer: str = Field("anonymous", min_length=1, max_length=255)


class DecisionOut(BaseModel):
    """One entry of a run's decision history."""

    id: int
    run_id: str
    item: DecidedItem = Field(description="What ``interval_id`` names: a twist interval or a swap")
    interval_id: int = Field(description="The id of the interval or swap within its run")
    decision: Decision
    note: str
    reviewer: str
    client: str = Field(description="The address the decision was sent from (as in the audit log)")
    created_at: datetime


class LockDecisionOut(BaseModel):
    """One entry of a run's foot lock decision history."""

    id: int
    run_id: str
    item: Literal["lock"] = Field("lock", description="A foot lock")
    lock_id: str = Field(description="The skate finding's id (``skate-left-120``)")
    decision: Decision
    note: str
    reviewer: str
    client: str = Field(description="The address the decision was sent from (as in the audit log)")
    created_at: datetime


class IntervalOut(BaseModel):
    """A twist interval of the run with its newest decision."""

    id: int
    joint: str
    side: str
    segment: str
    start_frame: int
    end_frame: int
    offset_deg: float
    confidence: float
    applied: bool = Field(description="Whether the run's own corrected take removes it")
    levels: list[tuple[int, int, float]]
    decision: Decision | None = Field(description="The newest decision, None without one")
    corrected: bool = Field(
        description="Whether the decided take removes it: accepted, or undecided and applied"
    )


class SwapOut(BaseModel):
    """A swap of a marker run (two labels exchanging trajectories) with its newest decision."""

    id: int = Field(description="Its position in the run's swap findings")
    markers: tuple[str, str]
    start_frame: int
    end_frame: int
    confidence: float
    applied: bool = Field(description="Whether the run's own corrected take repairs it")
    decision: Decision | None = Field(description="The newest decision, None without one")
    corrected: bool = Field(
        description="Whether the decided take repairs it: accepted, or undecided and applied"
    )


class LockOut(BaseModel):
    """The foot lock of a skate finding of the run (its feet step) with its newest decision.
    The decided download locks it when accepted, or undecided and locked by the run (its
    ``feet_apply``; cleanup is off by default, so a default run locks none)."""

    id: str = Field(description="The skate finding's id, as ``mocapqa feet fix --apply`` takes it")
    foot: Literal["left", "right"]
    joint: str = Field(description="The foot's rear point (a BVH's ankle joint, a heel marker)")
    start_frame: int
    end_frame: int
    value: float | None = Field(description="The skate's size in ``unit``")
    unit: str
    confidence: float | None = Field(description="That of the contact the skate lies in")
    speed_cm_s: float | None
    decision: Decision | None = Field(description="The newest decision, None without one")
    run_applied: bool = Field(
        False, description="Whether the run's own corrected take locks it (its feet_apply choice)"
    )
    applied: bool = Field(
        description="Whether the decided download locks it: accepted, or undecided and run_applied"
    )


class DecisionsOut(BaseModel):
    """A run's twist intervals or swaps and its foot locks with their decisions, and the
    decision histories."""

    run_id: str
    item: DecidedItem = Field(description="What the run's decisions are on")
    apply: str = Field(
        description="The run's rule for undecided items: its twist_apply choice, or "
        "'confident' for swaps"
    )
    intervals: list[IntervalOut] = Field(description="A motion run's twist intervals")
    swaps: list[SwapOut] = Field(description="A marker run's swaps")
    history: list[DecisionOut] = Field(
        description="Every decision on a twist interval or swap, newest first"
    )
    lock_apply: str = Field(
        "none", description="The run's rule for undecided foot locks: its feet_apply choice"
    )
    locks: list[LockOut] = Field(
        [], description="The foot locks of the run's skate findings (empty without the feet check)"
    )
    lock_history: list[LockDecisionOut] = Field(
        [], description="Every decision on a foot lock, newest first"
    )
