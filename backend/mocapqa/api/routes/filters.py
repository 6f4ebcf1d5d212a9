"""The run options and the filter registry (names, parameters, defaults, units) for the UI
forms."""

from __future__ import annotations

from fastapi import APIRouter

from mocapqa.api.errors import responses
from mocapqa.api.schemas import FilterInfo, RunOptionsInfo
from mocapqa.pipeline.filtering import filter_catalog
from mocapqa.pipeline.options import describe_options

__all__ = ["router"]

router = APIRouter(tags=["filters"])
"""Routes of this resource, included under ``/api/v1``."""


@router.get("/filters", responses=responses(401))
def list_filters() -> list[FilterInfo]:
    """Every registered filter (empty while the filters package is not installed)."""
    return [FilterInfo(**item) for item in filter_catalog()]


@router.get("/run-options", responses=responses(401))
def list_run_options() -> RunOptionsInfo:
    """The run options grouped by check (types, units, choices, bounds, defaults) and the
    named presets, as the re-run form shows them (``pipeline/options.py``)."""
    return RunOptionsInfo(**describe_options())
