"""Which contacts ``mocapqa feet fix --apply`` locks: ids of findings and contacts, the
confidence of a skate finding, and the choice itself."""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from mocapqa.errors import InputError
from mocapqa.feet.contacts import Contact
from mocapqa.feet.findings import Finding

__all__ = [
    "CONFIDENT",
    "RUN_APPLY_CHOICES",
    "add_ids",
    "check_apply",
    "choose_locks",
    "contact_id",
    "finding_confidence",
    "finding_id",
    "locked_findings",
]

RUN_APPLY_CHOICES = ("none", "confident", "skates")
"""The named choices of a run's ``feet_apply`` (besides ids): no lock (the default: cleanup is
off), the contacts of the confident skate findings, the contacts of every skate finding. A run
offers no ``all`` (every contact): its locks are its skate findings, each one a reviewer can
accept or reject."""

_SKATE_ID = re.compile(r"^skate-(left|right)-[0-9]{1,9}$")

CONFIDENT = 0.5
"""Contact confidence (:mod:`mocapqa.feet.contacts`) at and above which ``--apply confident``
locks a skate finding's contact: the foot sits at least halfway inside the release height and
speed over the contact on average. Set by hand, not tuned: 57 of the corpus' 62 skate findings
reach it."""


def finding_id(finding: Finding, skipped: int = 0) -> str:
    """The id of a finding in ``feet check --json`` and ``feet fix --apply``:
    ``"<kind>-<foot>-<first frame>"``, frames as in the take (``skipped`` bind-pose frames
    added)."""
    return f"{finding.kind}-{finding.foot}-{finding.start + skipped}"


def contact_id(contact: Contact, skipped: int = 0) -> str:
    """The id of a foot contact: ``"contact-<foot>-<first frame>"``, frames as in the take."""
    return f"contact-{contact.foot}-{contact.start + skipped}"


def _overlapping(finding: Finding, contacts: Sequence[Contact]) -> Contact | None:
    """The contact of the finding's foot it overlaps most (the first of equals), or None."""
    best, overlap = None, 0
    for c in contacts:
        shared = min(c.end, finding.end) - max(c.start, finding.start) + 1
        if c.foot == finding.foot and shared > overlap:
            best, overlap = c, shared
    return best


def finding_confidence(finding: Finding, contacts: Sequence[Contact]) -> float | None:
    """Confidence of the foot contact a skate finding lies in (the one it overlaps most), or
    None for other kinds or when no contact overlaps it."""
    if finding.kind != "skate":
        return None
    best = _overlapping(finding, contacts)
    return None if best is None else best.confidence


def _contact_of(finding: Finding, contacts: Sequence[Contact]) -> Contact:
    """The contact a skate finding's lock holds: the one it overlaps most, whose confidence
    is the finding's (:func:`finding_confidence`), else the finding's own frames."""
    best = _overlapping(finding, contacts)
    return Contact(finding.foot, finding.start, finding.end, 0.0) if best is None else best


def choose_locks(
    apply: str,
    contacts: Sequence[Contact],
    findings: Sequence[Finding],
    skipped: int = 0,
    confident: float = CONFIDENT,
) -> list[Contact]:
    """The contacts ``--apply`` asks to lock, in the check's frames.

    Parameters
    ----------
    apply : str
        ``"confident"`` (the contacts of skate findings whose contact confidence is at least
        ``confident``), ``"skates"`` (the contacts of every skate finding), ``"all"`` (every
        foot contact), ``"none"``, or comma-separated ids of skate findings
        (:func:`finding_id`) and contacts (:func:`contact_id`).
    contacts, findings : sequence
        From the feet check.
    skipped : int
        Leading bind-pose frames, added to the frames in ids.
    confident : float

    Returns
    -------
    list of Contact
        Unique, by foot and start frame.

    Raises
    ------
    InputError
        For an empty or unknown id, or the id of a finding that is not a skate.
    """
    skates = [f for f in findings if f.kind == "skate"]
    chosen: list[Contact]
    if apply == "none":
        chosen = []
    elif apply == "all":
        chosen = list(contacts)
    elif apply == "skates":
        chosen = [_contact_of(f, contacts) for f in skates]
    elif apply == "confident":
        chosen = [
            _contact_of(f, contacts)
            for f in skates
            if (finding_confidence(f, contacts) or 0.0) >= confident
        ]
    else:
        by_id = {finding_id(f, skipped): f for f in findings}
        by_contact = {contact_id(c, skipped): c for c in contacts}
        chosen = []
        for raw in apply.split(","):
            key = raw.strip()
            if key in by_contact:
                chosen.append(by_contact[key])
            elif key in by_id and by_id[key].kind == "skate":
                chosen.append(_contact_of(by_id[key], contacts))
            elif key in by_id:
                raise InputError(
                    f"Expected --apply ids of skate findings or contacts, got {key!r}, a "
                    f"{by_id[key].kind} finding (foot cleanup locks planted feet)"
                )
            else:
                known = [finding_id(f, skipped) for f in skates] + list(by_contact)[:4]
                raise InputError(
                    "Expected --apply confident, skates, all, none or comma-separated ids from "
                    f"`mocapqa feet check --json`, got {key!r} (ids here: "
                    f"{', '.join(known) or 'none'}{', ...' if len(by_contact) > 4 else ''})"
                )
    unique = {(c.foot, c.start): c for c in chosen}
    return [unique[k] for k in sorted(unique, key=lambda k: (k[1], k[0]))]


def locked_findings(
    apply: str, contacts: Sequence[Contact], findings: Sequence[Finding], skipped: int = 0
) -> set[str]:
    """The ids (:func:`finding_id`) of the skate findings whose contact ``apply`` locks
    (:func:`choose_locks`): a run's ``applied`` foot locks.

    Raises
    ------
    InputError
        As :func:`choose_locks`.
    """
    chosen = {(c.foot, c.start) for c in choose_locks(apply, contacts, findings, skipped)}
    return {
        finding_id(f, skipped)
        for f in findings
        if f.kind == "skate" and ((c := _contact_of(f, contacts)).foot, c.start) in chosen
    }


def check_apply(apply: str, named: Sequence[str] = RUN_APPLY_CHOICES) -> str:
    """``apply`` stripped when it is one of ``named`` or comma-separated ids of skate findings
    (``skate-left-120``), whether the take has them or not (:func:`choose_locks` checks that on
    the take). A run's locks are its skate findings, each one decided on its own: contact ids,
    which ``mocapqa feet fix --apply`` also takes, are refused here.

    Raises
    ------
    InputError
        Naming what was expected.
    """
    value = apply.strip()
    if value in named:
        return value
    keys = [key.strip() for key in value.split(",")]
    if not value or len(keys) > 1000 or not all(_SKATE_ID.match(key) for key in keys):
        raise InputError(
            f"Expected {', '.join(named)} or comma-separated ids of skate findings "
            f"('skate-left-120,skate-right-348'), got {apply[:80]!r}"
        )
    return ",".join(keys)


def add_ids(
    check: dict[str, Any],
    contacts: Sequence[Contact],
    findings: Sequence[Finding],
    skipped: int = 0,
) -> None:
    """Give each contact and finding of a feet check's JSON (``check["contacts"]``,
    ``check["findings"]``, in the order of ``contacts`` and ``findings``) its id, and each
    skate finding the confidence of its contact, in place."""
    for item, contact in zip(check["contacts"], contacts, strict=True):
        item["id"] = contact_id(contact, skipped)
    for item, finding in zip(check["findings"], findings, strict=True):
        item["id"] = finding_id(finding, skipped)
        if finding.kind == "skate":
            item["confidence"] = finding_confidence(finding, contacts)
