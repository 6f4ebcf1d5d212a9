"""Request and response models of the REST API (pydantic), separate from the store's rows."""

from __future__ import annotations

from datetime import datetime
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

from mocapqa.api.request_model import RequestModel
from mocapqa.core.rig import ROLE_KEYS
from mocapqa.errors import InputError
from mocapqa.pipeline.options import (
    CHECKS,
    MAX_POINTS_RANGE,
    Check,
    TwistMethod,
    check_checks,
    check_mapping,
)
from mocapqa.store.repository import ReviewStatus, RunStatus

__all__ = [
    "AnalysisOptionsIn",
    "ErrorOut",
    "FieldError",
    "FilterInfo",
    "HealthOut",
    "ReviewIn",
    "ReviewOut",
    "RunOut",
    "TakeCreatedOut",
    "TakeDetailOut",
    "TakeOut",
    "TakePageOut",
]


class FieldError(BaseModel):
    """One invalid field of a request."""

    field: str = Field(description="Where: e.g. query.offset or body.filter_params")
    message: str


class ErrorOut(BaseModel):
    """Every error answer (4xx): what went wrong, and where when it is known."""

    detail: str = Field(description="Expected X, got Y, and where")
    error: str = Field(description="Error class, e.g. ParseError, TooLargeError")
    field: str | None = Field(None, description="The field, column or option at fault")
    line: int | None = Field(None, description="1-based line of the file at fault")
    message: str | None = Field(None, description="The detail without the location")
    errors: list[FieldError] | None = Field(None, description="Every invalid field (422)")


class HealthOut(BaseModel):
    """Server health."""

    status: Literal["ok"] = "ok"
    version: str
    database: str


class AnalysisOptionsIn(RequestModel):
    """Options of a new run; omitted fields take their defaults."""

    model_config = ConfigDict(extra="forbid")

    checks: list[Check] = Field(
        list(CHECKS),
        max_length=len(CHECKS),
        json_schema_extra={"uniqueItems": True},
        description="The checks to run, each at most once",
    )
    twist_method: TwistMethod = "robust"
    twist_apply: str = Field(
        "confident",
        description="Twist intervals to remove: confident, all, none, or interval ids ('0,3'); "
        "checked by the run options (pipeline/options.py)",
    )
    filter_method: str | None = None
    filter_preset: str | None = None
    filter_params: dict[str, float | int | bool | str] = Field(default_factory=dict, max_length=64)
    max_points: int = Field(2000, ge=MAX_POINTS_RANGE[0], le=MAX_POINTS_RANGE[1])
    mapping: dict[str, str] = Field(
        default_factory=dict,
        max_length=len(ROLE_KEYS),
        description='Rig roles by hand, role key → joint name ({"left_upper_arm": "LeftArm"}); '
        "roles not named are found from the joint names and the skeleton's structure.",
    )

    @field_validator("checks")
    @classmethod
    def _checks_once(cls, value: list[Check]) -> list[Check]:
        try:
            check_checks(value)
        except InputError as e:
            raise ValueError(str(e)) from e
        return value

    @field_validator("mapping")
    @classmethod
    def _roles_are_known(cls, value: dict[str, str]) -> dict[str, str]:
        try:
            return check_mapping(value)
        except InputError as e:
            raise ValueError(str(e)) from e


class RunOut(BaseModel):
    """One analysis run."""

    id: str
    take_id: str
    status: RunStatus
    progress: int = Field(description="Percent complete, 0–100")
    step: str
    options: dict[str, Any]
    input_sha256: str
    version: str
    error: str | None
    summary: dict[str, Any] | None
    server_time_s: float | None
    attempts: int = Field(0, description="Times the run was started (a restart starts it again)")
    created_at: datetime
    started_at: datetime | None
    finished_at: datetime | None


class TakeOut(BaseModel):
    """A take in the list."""

    id: str
    name: str
    format: str
    kind: Literal["motion", "keypoints"]
    size_bytes: int
    sha256: str
    n_frames: int
    fps: float
    n_joints: int
    created_at: datetime
    latest_run_id: str | None
    status: RunStatus | None
    review_status: ReviewStatus
    n_findings: int | None
    owner_id: int | None = Field(
        None, description="The user who uploaded it (none before accounts or without users)."
    )


class TakeCreatedOut(TakeOut):
    """The answer to an upload: the take and the run that started."""

    run_id: str
    reading: dict[str, Any] | None = Field(
        None, description="How the take was read: chosen options, what was assumed and why."
    )


class TakeDetailOut(TakeOut):
    """One take with its runs and review history."""

    runs: list[RunOut]
    reviews: list[ReviewOut]
    reading: dict[str, Any] | None = Field(
        None,
        description="How the take was read: the options chosen at upload (fps, length_unit, "
        "root_translation), the frame rate and unit used, what the reader assumed "
        "(keypoints) and the root position reading with its reason (BVH).",
    )


class TakePageOut(BaseModel):
    """A page of takes."""

    items: list[TakeOut]
    total: int
    limit: int
    offset: int


class ReviewIn(RequestModel):
    """A review decision."""

    status: ReviewStatus
    notes: str = Field("", max_length=10_000)
    reviewer: str | None = Field(
        None,
        max_length=255,
        description="Ignored: the reviewer is the signed-in user (accepted so that clients "
        "that send a name are not refused)",
    )


class ReviewOut(BaseModel):
    """One entry of a take's review history."""

    id: int
    take_id: str
    status: ReviewStatus
    notes: str
    reviewer: str
    created_at: datetime


class FilterInfo(BaseModel):
    """One filter of the registry, for the UI forms."""

    name: str
    label: str
    description: str
    parameters: list[dict[str, Any]]
    presets: list[str]
    applies_to: list[str]


class RunOptionsInfo(BaseModel):
    """The run options for the UI form: fields grouped by check, the checks each kind of take
    can run (``motion``, ``markers``: a take of one of ``marker_formats``, ``keypoints``),
    named presets, and the rig role keys a ``mapping`` may name."""

    checks: list[str]
    take_checks: dict[str, list[str]]
    marker_formats: list[str]
    groups: list[dict[str, Any]]
    presets: dict[str, dict[str, Any]]
    role_keys: list[str]


TakeDetailOut.model_rebuild()
