"""Request and response models of the REST API (pydantic), separate from the store's rows."""

from __future__ import annotations

from datetime import datetime
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, Field, create_model, field_validator

from mocapqa.api.request_model import RequestModel
from mocapqa.errors import InputError, OptionError
from mocapqa.pipeline.option_fields import OptionField, json_value
from mocapqa.pipeline.options import AnalysisOptions, ParamValue, option_fields
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
    "options_request_model",
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


def _request_type(field: OptionField) -> Any:
    """The type a request gives the option ``field``, from its kind and choices."""
    spec = field.spec
    names: Any = Literal.__getitem__(spec.choices) if spec.choices else str
    kinds: dict[str, Any] = {
        "names": list.__class_getitem__(names),
        "text": str if spec.open_choices else names,
        "int": int,
        "params": dict[str, ParamValue],
        "mapping": dict[str, str],
    }
    value = kinds[spec.kind]
    return value | None if spec.nullable else value


def _request_field(field: OptionField) -> Any:
    """The pydantic field of the option ``field``: its default, bounds and help."""
    spec = field.spec
    limits: dict[str, Any] = {"description": spec.help}
    if spec.bounds is not None:
        limits["ge"], limits["le"] = spec.bounds
    if spec.max_items is not None:
        limits["max_length"] = spec.max_items
    if spec.kind == "names":
        limits["json_schema_extra"] = {"uniqueItems": True}
    if isinstance(field.default, dict):
        return Field(default_factory=dict, **limits)
    return Field(json_value(field.default), **limits)


def _request_check(field: OptionField) -> Any:
    """A validator running the option's own check in the request model (a 422 naming it)."""
    check = field.spec.check

    def checked(cls: type[BaseModel], value: Any) -> Any:
        del cls
        try:
            kept = check(value) if check is not None else value
        except OptionError as e:
            raise ValueError(e.message) from e
        except InputError as e:
            raise ValueError(str(e)) from e
        return type(value)(kept)

    return field_validator(field.name)(classmethod(checked))


def options_request_model(cls: type[AnalysisOptions] = AnalysisOptions) -> type[RequestModel]:
    """The request model of a new run's options, generated from the options ``cls`` declares
    (:func:`mocapqa.pipeline.options.option_fields`): every option a run request carries, with
    its type, default, bounds and help; the checks that need no registry nor take run here."""
    fields = [f for f in option_fields(cls) if f.spec.requested]
    checks = {f"_check_{f.name}": _request_check(f) for f in fields if f.spec.check_in_request}
    definitions: dict[str, Any] = {f.name: (_request_type(f), _request_field(f)) for f in fields}
    return create_model(
        "AnalysisOptionsIn",
        __base__=RequestModel,
        __module__=__name__,
        __doc__="Options of a new run; omitted fields take their defaults.",
        __validators__=checks,
        **definitions,
    )


if TYPE_CHECKING:
    AnalysisOptionsIn = RequestModel
else:
    AnalysisOptionsIn = options_request_model()
    """Options of a new run (``POST /takes/{id}/runs``), generated from the declaration."""


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
    can run (``motion``, ``markers``: a take of one of ``marker_formats``, ``keypoints``) and
    the filters (``target`` as ``GET /filters`` names it, ``default`` the filter run when none
    is chosen), named presets, and the rig role keys a ``mapping`` may name."""

    checks: list[str]
    take_checks: dict[str, list[str]]
    take_filters: dict[str, dict[str, str | None]]
    marker_formats: list[str]
    groups: list[dict[str, Any]]
    presets: dict[str, dict[str, Any]]
    role_keys: list[str]


TakeDetailOut.model_rebuild()
