"""Turning store rows into response models."""

from __future__ import annotations

from typing import Any

from mocapqa.api.schemas import ReviewOut, RunOut, TakeOut
from mocapqa.core.text import display_name

__all__ = ["review_out", "run_out", "take_fields"]


def take_fields(row: dict[str, Any]) -> dict[str, Any]:
    """The fields of :class:`TakeOut` from a take row (with latest run and review)."""
    summary = row.get("summary") or {}
    fields = {name: row.get(name) for name in TakeOut.model_fields if name in row}
    fields["n_findings"] = summary.get("n_findings") if isinstance(summary, dict) else None
    fields.setdefault("latest_run_id", None)
    fields.setdefault("status", None)
    fields["review_status"] = row.get("review_status") or "unreviewed"
    fields["name"] = display_name(str(row.get("name") or "")) or str(row.get("file_name"))
    return fields


def run_out(row: dict[str, Any]) -> RunOut:
    """A run row as :class:`RunOut`."""
    return RunOut.model_validate(row)


def review_out(row: dict[str, Any]) -> ReviewOut:
    """A review row as :class:`ReviewOut`."""
    return ReviewOut.model_validate({**row, "reviewer": display_name(str(row["reviewer"]))})
