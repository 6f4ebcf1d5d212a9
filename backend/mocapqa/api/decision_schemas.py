"""Request and response models of the twist-interval decisions (``routes/decisions.py``)."""

from __future__ import annotations

from datetime import datetime
from typing import Literal

from pydantic import BaseModel, Field

from mocapqa.api.request_model import RequestModel

__all__ = ["DecisionIn", "DecisionOut", "DecisionsOut", "IntervalOut"]

Decision = Literal["accept", "reject"]


class DecisionIn(RequestModel):
    """A reviewer's decision on one twist interval."""

    decision: Decision
    note: str = Field("", max_length=10_000)
    reviewer: str = Field("anonymous", min_length=1, max_length=255)


class DecisionOut(BaseModel):
    """One entry of a run's decision history."""

    id: int
    run_id: str
    interval_id: int
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


class DecisionsOut(BaseModel):
    """A run's twist intervals with their decisions, and the decision history."""

    run_id: str
    apply: str = Field(description="The run's twist_apply choice (for undecided intervals)")
    intervals: list[IntervalOut]
    history: list[DecisionOut] = Field(description="Every decision, newest first")
