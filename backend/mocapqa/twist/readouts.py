"""The readout of a twist interval: one line saying what the default does with it and why.

:func:`decision_readout` reads an interval's ``evidence`` (as
:meth:`mocapqa.twist.choice.TwistInterval.to_json` writes it): the rule of
:data:`mocapqa.twist.confidence.RULES` that decided, its figures, and how a shoot's reviewer
prior moved the probability (:mod:`mocapqa.twist.reviewer_prior`), for the findings list and
the report.
"""

from __future__ import annotations

from mocapqa.twist.confidence import APPLY_THRESHOLD

__all__ = ["decision_readout"]

_READOUTS = {
    "calibrated": "{verdict}: calibrated probability {calibrated:.2f} (applied from 0.50)",
    "anatomy": (
        "{verdict}: the raw roll is {anatomy_deg:.0f}° further outside the natural range than "
        "the corrected one (calibrated {calibrated:.2f})"
    ),
    "anatomy_against": (
        "{verdict}: the correction would take a natural roll outside the range "
        "(calibrated {calibrated:.2f})"
    ),
    "repetition": "{verdict}: other strong intervals on this joint (calibrated {calibrated:.2f})",
    "min_evidence": (
        "{verdict}: too small, or the roll outside contradicts its jumps "
        "(calibrated {calibrated:.2f})"
    ),
    "end_evidence": (
        "{verdict}: runs to the take's end with a small level and a poor counter-rotation "
        "(calibrated {calibrated:.2f})"
    ),
    "uncalibrated": "{verdict}: no calibrated probability",
}


_VERDICTS = {"applied": "the default applies it", "listed": "the default only reports it"}
"""What the default does with an interval, in words that stay true whatever a run applied (a
run with another ``apply`` says what it did beside the readout)."""


def decision_readout(evidence: dict[str, float | str]) -> str:
    """One line saying what the default (``apply="confident"``) does with an interval and which
    evidence decided (its ``evidence`` as :meth:`mocapqa.twist.choice.TwistInterval.to_json`
    writes it): for the findings list and the report, whatever the run applied.

    Examples: ``"the default applies it: the raw roll is 31° further outside the natural range
    than the corrected one (calibrated 0.14)"``; ``"the default only reports it: smaller than
    this rig's natural upper arm roll (p99 16.5°)"``; with a reviewer prior, ``"the default
    applies it: calibrated probability 0.14, raised to 0.75 by 12 accepted intervals on this
    joint in this shoot, which changed the default (applied from 0.50)"``. Empty when nothing
    was recorded (the paper's method).
    """
    rule = str(evidence.get("rule", ""))
    if not rule:
        return ""
    verdict = _VERDICTS.get(str(evidence.get("default", "listed")), _VERDICTS["listed"])
    reviewers = _reviewers_text(evidence)
    suffix = f"; probability {reviewers}" if reviewers else ""
    if "reason" in evidence:
        return f"{verdict}: {evidence['reason']}{suffix}"
    if reviewers and rule == "calibrated":
        calibrated = float(evidence.get("calibrated", 0.0))
        moved = float(evidence["reviewer_probability"])
        changed = (calibrated >= APPLY_THRESHOLD) != (moved >= APPLY_THRESHOLD)
        which = ", which changed the default" if changed else ""
        return (
            f"{verdict}: calibrated probability {calibrated:.2f}, {reviewers}{which} "
            f"(applied from {APPLY_THRESHOLD:.2f})"
        )
    values = {"calibrated": 0.0, "anatomy_deg": 0.0, **evidence, "verdict": verdict}
    template = _READOUTS.get(rule, "{verdict}: " + rule.replace("_", " "))
    return template.format(**values) + suffix


def _reviewers_text(evidence: dict[str, float | str]) -> str:
    """How the reviewer prior moved an interval's probability (``"raised to 0.75 by 12
    accepted intervals on this joint in this shoot (1 rejected)"``), empty without one."""
    if "reviewer_probability" not in evidence:
        return ""
    accepted = int(float(evidence.get("reviewer_accepted", 0.0)))
    rejected = int(float(evidence.get("reviewer_rejected", 0.0)))
    before = round(float(evidence.get("calibrated", 0.0)), 2)
    after = round(float(evidence["reviewer_probability"]), 2)
    if after == before:
        counts = [
            f"{n} {word}" for n, word in ((accepted, "accepted"), (rejected, "rejected")) if n
        ]
        plural = "" if accepted + rejected == 1 else "s"
        return f"not moved by {' and '.join(counts)} interval{plural} on this joint in this shoot"
    raised = after > before
    main, other = (accepted, rejected) if raised else (rejected, accepted)
    word, other_word = ("accepted", "rejected") if raised else ("rejected", "accepted")
    plural = "" if main == 1 else "s"
    tail = f" ({other} {other_word})" if other else ""
    return (
        f"{'raised' if raised else 'lowered'} to {after:.2f} by {main} {word} interval{plural} "
        f"on this joint in this shoot{tail}"
    )
