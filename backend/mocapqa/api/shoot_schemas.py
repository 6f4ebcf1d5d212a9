"""Request and response models of the shoot routes (pydantic)."""

from __future__ import annotations

from datetime import datetime
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from mocapqa.api.request_model import RequestModel
from mocapqa.limits.catalog import MODEL_NAME_PATTERN
from mocapqa.store.repository import ReviewStatus, RunStatus

__all__ = [
    "HeatmapOut",
    "ImportOut",
    "LimitsModelIn",
    "LimitsModelOut",
    "LimitsRerunsOut",
    "NextTakeOut",
    "ProgressOut",
    "ShootIn",
    "ShootOut",
    "ShootTakeOut",
    "ShootTakePageOut",
]


class ShootIn(RequestModel):
    """A shoot's name (create or rename)."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(min_length=1, max_length=255)


class ShootOut(BaseModel):
    """A shoot with its counts."""

    id: str
    name: str
    created_at: datetime
    n_takes: int
    n_frames: int
    status_counts: dict[str, int] = Field(description="Takes per latest run status")
    review_counts: dict[str, int] = Field(description="Takes per review status")
    owner_id: int | None = Field(
        None,
        description="The user who made it, who may rename and delete it besides admins (none "
        "for shoots made before shoots had owners, or without users).",
    )
    limits_model: str = Field(
        "default",
        description="The joint-limits model the runs of its takes use (`GET /limits-models`); "
        "an admin chooses it",
    )
    limits_stale_takes: int = Field(
        0,
        description="Motion takes whose latest run checked joint limits with another model "
        "than `limits_model` (made before the shoot's model was changed); an admin runs them "
        "again with `POST /shoots/{id}/limits-reruns`",
    )


class ShootTakeOut(BaseModel):
    """One row of a shoot's take table: the QA summary (docs/qa-summary.md) and review."""

    take_id: str
    name: str
    kind: Literal["motion", "keypoints"]
    format: str
    fps: float
    n_joints: int
    created_at: datetime
    run_id: str | None
    status: RunStatus | None
    review_status: ReviewStatus
    reviewer: str | None
    score: float | None = Field(description="QA score, 0–100 (100: nothing found)")
    n_frames: int | None
    duration_s: float | None
    rig: str | None
    twist_intervals: int | None
    corrected_joint_frames: int | None
    limb_spins: int | None = Field(
        default=None, description="Limb spins and flips reported (never corrected)"
    )
    violation_share: float | None
    worst_joint: str | None
    filter_residual_mm: float | None
    missing_share: float | None
    n_findings: int | None
    foot_skates: int | None = Field(
        default=None,
        description="Foot skate findings (a planted foot sliding); null when the feet were not "
        "checked (or the run was made before these figures)",
    )
    foot_worst_skate: float | None = Field(
        default=None,
        description="The largest foot skate, in `foot_skate_unit`; null when no skate was found "
        "(or the feet were not checked)",
    )
    foot_skate_unit: str | None = Field(
        default=None,
        description="Unit of `foot_worst_skate`: cm, or % of the body height estimated from the "
        "leg length when the take's unit does not convert to cm (BVH stores none)",
    )
    foot_penetrations: int | None = Field(
        default=None, description="Floor penetration findings (a foot below the floor)"
    )
    foot_floating: int | None = Field(
        default=None, description="Floating findings (a still foot above the floor)"
    )
    foot_worst_skate_pct: float | None = Field(
        default=None,
        description="The largest foot skate in % of the body height estimated from the leg "
        "length, whatever the take's unit: the figure that compares across takes (sorting by "
        "`foot_worst_skate` sorts by it); null when no skate was found, the feet were not "
        "checked, or the run (a take in cm) was made before this figure",
    )
    joint_violations: dict[str, float] | None


class ShootTakePageOut(BaseModel):
    """A page of a shoot's take table."""

    items: list[ShootTakeOut]
    total: int
    limit: int
    offset: int


class ImportOut(BaseModel):
    """What an import did."""

    created: list[dict[str, str]]
    skipped: list[dict[str, str]]
    failed: list[dict[str, str]]


class ProgressOut(BaseModel):
    """Analysis progress of a shoot's takes."""

    shoot_id: str
    n_takes: int
    status_counts: dict[str, int]
    frames_done: int
    finished: bool


class HeatmapOut(BaseModel):
    """Joint × take share of frames outside the joint limits, for a page of takes."""

    joints: list[str] = Field(description="Joints violated on this page, most violated first")
    takes: list[dict[str, str | float | None]] = Field(
        description="The page's takes (take_id, name, score), in the table's order"
    )
    values: list[list[float | None]] = Field(
        description="joints × takes shares of frames outside the limits, in [0, 1]; null where "
        "the limits check did not run"
    )
    total: int = Field(description="Takes in the shoot that pass the filters")
    limit: int = Field(description="Takes per page asked for")
    offset: int = Field(description="Takes before this page")


class NextTakeOut(BaseModel):
    """The next take needing review (None when none is left) and how many remain."""

    take: ShootTakeOut | None
    remaining: int


class LimitsModelIn(RequestModel):
    """The limits model a shoot's runs use, by name."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(
        min_length=1,
        max_length=64,
        pattern=MODEL_NAME_PATTERN,
        description="A name from `GET /limits-models`",
        examples=["default", "canonical"],
    )


class LimitsRerunsOut(BaseModel):
    """What `POST /shoots/{id}/limits-reruns` queued."""

    limits_model: str = Field(description="The shoot's model, which the new runs use")
    queued: list[dict[str, str]] = Field(
        description="One entry per new run: `take_id`, `run_id` (oldest take first)"
    )
    remaining: int = Field(
        description="Takes still to run again: beyond the caller's free places in the run "
        "queue (`max_queued_runs_per_user`); the same request queues them once runs finish"
    )


class LimitsModelOut(BaseModel):
    """A choosable joint-limits model (``mocapqa.limits.catalog``)."""

    name: str
    kind: Literal["default", "shipped", "registered"] = Field(
        description="default: the shipped choice per rig; shipped: a file shipped with mocapqa; "
        "registered: built with `mocapqa limits build` and registered in the data folder"
    )
    frame: Literal["per rig", "canonical", "rig"] = Field(
        description="canonical: any rig with limb roles; rig: only its own rig's skeleton"
    )
    rig_family: str
    n_takes: int = Field(description="Takes the model was built from (0 for the default)")
    n_frames: int = Field(description="Frames the model was built from (0 for the default)")
