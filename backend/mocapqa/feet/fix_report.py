"""The report of ``mocapqa feet fix``: each finding and contact, locked or not, with its slide
before and after.

Slides are the pivot's planted travel over a contact (:func:`mocapqa.feet.lock.planted_travel`),
in take units, in centimetres when the unit converts (``*_cm``, else null) and over the body
height estimated from the leg length (``*_rel_height``), as in ``mocapqa feet check``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from mocapqa.feet.contacts import Contact
from mocapqa.feet.findings import Finding
from mocapqa.feet.fix_choice import contact_id, finding_confidence, finding_id
from mocapqa.feet.points import FootPoints, cm_per_unit

__all__ = ["fix_report_json"]


def _round(value: float | None, digits: int = 5) -> float | None:
    return None if value is None else round(float(value), digits)


@dataclass(frozen=True, slots=True)
class _Scale:
    """The units a slide or size is given in: take units, centimetres, body height."""

    to_cm: float | None
    height: float

    def sizes(self, prefix: str, value: float | None) -> dict[str, float | None]:
        """``prefix``, ``prefix_cm`` and ``prefix_rel_height`` of one value."""
        return {
            prefix: _round(value),
            f"{prefix}_cm": None
            if value is None or self.to_cm is None
            else _round(value * self.to_cm, 3),
            f"{prefix}_rel_height": None if value is None else _round(value / self.height),
        }


@dataclass(frozen=True, slots=True)
class _Slides:
    """Per contact of the input's check: the slide before and after, clamped frames, reach."""

    before: Sequence[float]
    after: Sequence[float]
    clamped: Sequence[int]
    miss: Sequence[float]


def _contact_index(contacts: Sequence[Contact], foot: str, start: int, end: int) -> int | None:
    """The contact of ``foot`` overlapping ``start``–``end`` the most, or None."""
    best, overlap = None, 0
    for i, c in enumerate(contacts):
        shared = min(c.end, end) - max(c.start, start) + 1
        if c.foot == foot and shared > overlap:
            best, overlap = i, shared
    return best


def _skate_after(
    finding: Finding, findings_after: Sequence[Finding], scale: _Scale, skipped: int
) -> dict[str, Any] | None:
    """The largest skate of the output overlapping ``finding``, or None."""
    foot, start, end = finding.foot, finding.start, finding.end
    hits = [f for f in findings_after if f.kind == "skate" and f.foot == foot
            and f.start <= end and f.end >= start]  # fmt: skip
    if not hits:
        return None
    worst = max(hits, key=lambda f: f.size)
    return {"start": worst.start + skipped, "end": worst.end + skipped,
            **scale.sizes("size", worst.size)}  # fmt: skip


def _contact_items(
    contacts: Sequence[Contact],
    locked_keys: set[tuple[str, int]],
    slides: _Slides,
    scale: _Scale,
    skipped: int,
) -> list[dict[str, Any]]:
    """The ``contacts`` of :func:`fix_report_json`."""
    return [
        {
            "id": contact_id(c, skipped),
            "foot": c.foot,
            "start": c.start + skipped,
            "end": c.end + skipped,
            "confidence": c.confidence,
            "applied": (c.foot, c.start) in locked_keys,
            "clamped_frames": int(slides.clamped[i]),
            **scale.sizes("reach_miss", slides.miss[i]),
            **scale.sizes("slide_before", slides.before[i]),
            **scale.sizes("slide_after", slides.after[i]),
        }
        for i, c in enumerate(contacts)
    ]


def _finding_item(
    finding: Finding,
    contacts: Sequence[Contact],
    locked_keys: set[tuple[str, int]],
    slides: _Slides,
    findings_after: Sequence[Finding],
    scale: _Scale,
    skipped: int,
) -> dict[str, Any]:
    """One finding of :func:`fix_report_json`, with the slide of its contact (skate)."""
    f = finding
    item: dict[str, Any] = {
        "id": finding_id(f, skipped),
        "kind": f.kind,
        "foot": f.foot,
        "start": f.start + skipped,
        "end": f.end + skipped,
        "confidence": finding_confidence(f, contacts),
        **scale.sizes("size", f.size),
    }
    index = _contact_index(contacts, f.foot, f.start, f.end) if f.kind == "skate" else None
    if index is None:
        item.update(applied=False, contact=None, slide_before=None, slide_after=None)
    else:
        c = contacts[index]
        item.update(
            applied=(c.foot, c.start) in locked_keys,
            contact=contact_id(c, skipped),
            **scale.sizes("slide_before", slides.before[index]),
            **scale.sizes("slide_after", slides.after[index]),
            skate_after=_skate_after(f, findings_after, scale, skipped),
        )
    return item


def fix_report_json(
    points: FootPoints,
    contacts: Sequence[Contact],
    findings: Sequence[Finding],
    locked: Sequence[Contact],
    before: Sequence[float],
    after: Sequence[float],
    clamped: Sequence[int],
    miss: Sequence[float],
    findings_after: Sequence[Finding],
    skipped: int = 0,
) -> dict[str, Any]:
    """The ``feet fix`` report as a JSON-ready dict.

    Parameters
    ----------
    points : FootPoints
        Of the input take (units and leg length).
    contacts, findings : sequence
        The feet check of the input, frames of the check.
    locked : sequence of Contact
        The contacts locked.
    before, after : sequence of float
        Per contact of ``contacts``, the slide in the input and in the output, take units.
    clamped : sequence of int
        Per contact of ``contacts``, frames (with its blends) whose target was out of reach.
    miss : sequence of float
        Per contact of ``contacts``, the largest distance the ankle fell short, take units.
    findings_after : sequence of Finding
        The feet check of the output.
    skipped : int
        Leading bind-pose frames, added to every frame.

    Returns
    -------
    dict
        ``contacts`` and ``findings`` with ``id``, frames, ``applied``, ``slide_before`` and
        ``slide_after`` (skate findings: of their contact) and ``skate_after`` (the skate the
        check still finds on the output overlapping it, or null); a ``summary``.
    """
    scale = _Scale(cm_per_unit(points.length_unit), points.body_height)
    locked_keys = {(c.foot, c.start) for c in locked}
    slides = _Slides(before, after, clamped, miss)
    return {
        "length_unit": points.length_unit,
        "cm_per_unit": scale.to_cm,
        "body_height_estimate": _round(scale.height),
        "bind_pose_frames": skipped,
        "contacts": _contact_items(contacts, locked_keys, slides, scale, skipped),
        "findings": [
            _finding_item(f, contacts, locked_keys, slides, findings_after, scale, skipped)
            for f in findings
        ],
        "summary": {
            "contacts_locked": len(locked_keys),
            "clamped_frames": int(sum(clamped)),
            "skate_findings_before": sum(f.kind == "skate" for f in findings),
            "skate_findings_after": sum(f.kind == "skate" for f in findings_after),
        },
    }
