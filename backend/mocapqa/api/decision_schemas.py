"""Request and response models of the decisions on twist intervals and swaps
(``routes/decisions.py``)."""

from __future__ import annotations

from datetime import datetime

from pydantic import BaseModel, Field

from mocapqa.api.request_model import RequestModel
from mocapqa.store.decisions import DecidedItem, Decision

__all__ = ["DecisionIn", "DecisionOut", "DecisionsOut", "IntervalOut", "SwapOut"]


class DecisionIn(RequestModel):
    """A reviewer's decision on one twist interval or swap."""

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


class DecisionsOut(BaseModel):
    """A run's twist intervals or swaps with their decisions, and the decision history."""

    run_id: str
    item: DecidedItem = Field(description="What the run's decisions are on")
    apply: str = Field(
        description="The run's rule for undecided items: its twist_apply choice, or "
        "'confident' for swaps"
    )
    intervals: list[IntervalOut] = Field(description="A motion run's twist intervals")
    swaps: list[SwapOut] = Field(description="A marker run's swaps")
    history: list[DecisionOut] = Field(description="Every decision, newest first")
