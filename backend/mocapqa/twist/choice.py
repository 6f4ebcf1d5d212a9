"""Which detected twist intervals a refinement applies, and their report entries.

``apply`` is one of :data:`APPLY_CHOICES` or a set of interval ids. Ids number the intervals of
a take in chain, then frame order. ``confident`` applies intervals whose calibrated probability
is at least :data:`mocapqa.twist.confidence.APPLY_THRESHOLD` and that pass the minimum-evidence
rule :func:`mocapqa.twist.confidence.has_evidence`, or that the anatomy evidence supports, and
never those it contradicts (:func:`mocapqa.twist.confidence.decide`; methods without a
calibrated confidence apply all); an interval smaller than its rig segment's natural roll
(:mod:`mocapqa.twist.natural_roll`) is never applied by ``confident``. Each interval's
``evidence`` records which evidence decided, and why when it is the natural roll.
Each :class:`TwistInterval` lists its ``levels``: the stretches of constant offset, so the
refined take is exactly the raw one with the applied levels removed.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError
from mocapqa.twist.anatomy import AnatomyEvidence
from mocapqa.twist.angles import ChainGeometry
from mocapqa.twist.confidence import decide
from mocapqa.twist.detect import DetectedInterval

__all__ = [
    "APPLY_CHOICES",
    "MAX_APPLY_IDS",
    "TwistInterval",
    "choose_intervals",
    "decision_readout",
    "parse_apply",
]

APPLY_CHOICES = ("confident", "all", "none")
"""Which intervals a refinement applies, besides an explicit list of interval ids:
``confident`` (calibrated probability ≥ :data:`mocapqa.twist.confidence.APPLY_THRESHOLD` and the
minimum-evidence rule, the default), ``all`` or ``none``."""


_IDS = re.compile(r"[0-9]+(,[0-9]+)*")


MAX_APPLY_IDS = 10_000
"""Most interval ids an ``apply`` list may name (a take has far fewer intervals)."""


def parse_apply(value: str | frozenset[int]) -> str | frozenset[int]:
    """One of :data:`APPLY_CHOICES`, or the set of interval ids in ``"3,7"``.

    Raises
    ------
    InputError
        For anything else.
    """
    if isinstance(value, frozenset):
        return value
    text = str(value).strip()
    if text in APPLY_CHOICES:
        return text
    if len(text) > 8 * MAX_APPLY_IDS:  # before splitting: a 590 KB list was stored and queued
        raise InputError(
            f"Expected at most {MAX_APPLY_IDS:,} interval ids, got {len(text):,} characters"
        )
    # ASCII digits only: int() would also read "1_0" as 10 and other scripts' digits.
    ids = (
        frozenset(int(v) for v in text.split(","))
        if _IDS.fullmatch(text.replace(" ", ""))
        else frozenset({-1})
    )
    if len(ids) > MAX_APPLY_IDS:
        raise InputError(f"Expected at most {MAX_APPLY_IDS:,} interval ids, got {len(ids):,}")
    if not ids or min(ids) < 0:
        raise InputError(
            f"Expected apply to be one of {list(APPLY_CHOICES)} or interval ids like '0,3', "
            f"got {value!r}"
        )
    return ids


@dataclass(frozen=True, slots=True)
class TwistInterval:
    """An error interval on one target (parent) joint.

    Parameters
    ----------
    joint : str
        Name of the parent joint whose twist is offset.
    side : str
        "left" or "right".
    segment : str
        Role of the joint ("clavicle", "upper_arm", "forearm", "upper_leg", "lower_leg").
    start_frame, end_frame : int
        First and last frame of the interval (inclusive, 0-based).
    offset_deg : float
        Mean twist offset over the interval, degrees (−180, 180].
    confidence : float
        Calibrated probability that applying the interval is right, [0, 1].
    id : int
        Position in the take's interval list (chain, then frame order), for ``apply``.
    applied : bool
        Whether the refinement removed it.
    levels : tuple of (int, int, float)
        ``(start_frame, end_frame, offset_deg)`` of each stretch of constant offset: the
        refined take is the raw one with exactly these removed, so they also undo it.
    evidence : tuple of (str, float or str), optional
        What ``apply="confident"`` decided on: ``calibrated`` (the probability), ``anatomy_deg``
        (degrees the correction brings the parent's twist back inside its natural range:
        raw minus corrected distance beyond it; absent when no limits model reads the joint),
        ``child_anatomy_deg`` (the same for the child's rotation), ``natural_roll_deg`` (the
        natural roll level of the rig's segment, when one is stored), ``rule`` (one of
        :data:`mocapqa.twist.confidence.RULES`) and, for the rule ``natural_roll``, ``reason``
        (readable). Empty for the paper's method.
    """

    joint: str
    side: str
    segment: str
    start_frame: int
    end_frame: int
    offset_deg: float
    confidence: float
    id: int = 0
    applied: bool = True
    levels: tuple[tuple[int, int, float], ...] = ()
    evidence: tuple[tuple[str, float | str], ...] = ()

    def to_json(self) -> dict[str, Any]:
        """The interval as a JSON-ready dict (``evidence`` only when recorded)."""
        out = {
            "id": self.id,
            "joint": self.joint,
            "side": self.side,
            "segment": self.segment,
            "start_frame": self.start_frame,
            "end_frame": self.end_frame,
            "offset_deg": round(self.offset_deg, 4),
            "confidence": round(self.confidence, 4),
            "applied": self.applied,
            "levels": [[a, b, round(v, 6)] for a, b, v in self.levels],
        }
        if self.evidence:
            out["evidence"] = {
                k: round(v, 4) if isinstance(v, float) else v for k, v in self.evidence
            }
        return out


def choose_intervals(
    found: Sequence[DetectedInterval],
    detected: FloatArray,
    geometries: Sequence[ChainGeometry],
    names: Sequence[str],
    choice: str | frozenset[int],
    calibrated: bool,
    anatomy: AnatomyEvidence | None = None,
    natural_deg: Sequence[float] | None = None,
) -> tuple[FloatArray, list[TwistInterval]]:
    """The offsets to remove and the report entry of every interval.

    Parameters
    ----------
    found : sequence of DetectedInterval
        In chain, then frame order (their position is their id).
    detected : ndarray, shape (F, C)
        Offsets of every interval found, radians.
    geometries : sequence of ChainGeometry, length C
    names : sequence of str
        Joint names.
    choice : str or frozenset of int
        From :func:`parse_apply`.
    calibrated : bool
        Whether the confidences are calibrated probabilities (else ``confident`` applies all).
    anatomy : AnatomyEvidence, optional
        Anatomy evidence of each interval of ``found`` (:mod:`mocapqa.twist.anatomy`).
    natural_deg : sequence of float, optional
        Natural roll level of each interval's rig segment, degrees (0: none stored;
        :mod:`mocapqa.twist.natural_roll`); None: no natural roll rule.

    Returns
    -------
    offsets : ndarray, shape (F, C)
        The applied intervals' offsets, 0 elsewhere.
    intervals : list of TwistInterval

    Raises
    ------
    InputError
        For an interval id the take does not have.
    """
    _check_ids(choice, len(found))
    offsets = np.zeros_like(detected)
    intervals = []
    probability = np.array([i.confidence for i in found], dtype=np.float64)
    features = [i.features if calibrated else () for i in found]
    chains = [i.chain for i in found]
    confident, rules = decide(
        probability, features, anatomy, chains=chains, sides=[i.side for i in found],
        natural_deg=natural_deg,
    )  # fmt: skip
    for k, i in enumerate(found):
        applied = _is_applied(choice, k, bool(confident[k]))
        evidence: tuple[tuple[str, float | str], ...] = ()
        if features[k]:
            natural = 0.0 if natural_deg is None else float(natural_deg[k])
            segment = geometries[i.chain].chain.segment
            evidence = _evidence(i, k, anatomy, natural, rules[k], bool(confident[k]), segment)
        rows = slice(i.start_frame, i.end_frame + 1)
        if applied:
            offsets[rows, i.chain] = detected[rows, i.chain]
        geometry = geometries[i.chain]
        intervals.append(
            TwistInterval(
                joint=names[geometry.chain.parent],
                side=geometry.chain.side,
                segment=geometry.chain.segment,
                start_frame=i.start_frame,
                end_frame=i.end_frame,
                offset_deg=float(np.rad2deg(i.offset_rad)),
                confidence=float(i.confidence),
                id=k,
                applied=applied,
                levels=_levels(detected[rows, i.chain], i.start_frame),
                evidence=evidence,
            )
        )
    return offsets, intervals


def _is_applied(choice: str | frozenset[int], k: int, confident: bool) -> bool:
    """Whether ``choice`` (from :func:`parse_apply`) applies interval ``k``, whose default is
    ``confident``."""
    if isinstance(choice, frozenset):
        return k in choice
    if choice == "confident":
        return confident
    return choice != "none"


def _check_ids(choice: str | frozenset[int], n_found: int) -> None:
    """Refuse interval ids in ``choice`` beyond the ``n_found`` intervals of the take.

    Raises
    ------
    InputError
        For an interval id the take does not have.
    """
    if isinstance(choice, frozenset) and choice and max(choice) >= n_found:
        if not n_found:
            raise InputError(
                f"Expected no interval ids in apply on a take with no twist interval, got "
                f"{sorted(choice)}"
            )
        raise InputError(f"Expected interval ids 0 to {n_found - 1} in apply, got {sorted(choice)}")


def _evidence(
    interval: DetectedInterval,
    k: int,
    anatomy: AnatomyEvidence | None,
    natural: float,
    rule: str,
    confident: bool,
    segment: str,
) -> tuple[tuple[str, float | str], ...]:
    """What decided the default for interval ``k``: its calibrated probability, its anatomy
    readings (degrees), its segment's natural roll level (degrees, 0: none), the deciding
    ``rule`` and whether the default applies it."""
    evidence: tuple[tuple[str, float | str], ...] = (("calibrated", float(interval.confidence)),)
    if anatomy is not None and anatomy.checked[k]:
        evidence += (
            ("anatomy_deg", float(anatomy.raw_deg[k] - anatomy.fixed_deg[k])),
            ("child_anatomy_deg", float(anatomy.child_raw_deg[k] - anatomy.child_fixed_deg[k])),
        )
    if natural > 0.0:
        evidence += (("natural_roll_deg", natural),)
    evidence += (("rule", rule), ("default", "applied" if confident else "listed"))
    if rule == "natural_roll":
        name = segment.replace("_", " ")
        evidence += (
            ("reason", f"smaller than this rig's natural {name} roll (p99 {natural:.1f}°)"),
        )
    return evidence


def _levels(values: FloatArray, start_frame: int) -> tuple[tuple[int, int, float], ...]:
    """Each run of one non-zero level in an interval's offsets ``values`` (radians, from frame
    ``start_frame``): first and last frame and the level in degrees."""
    cuts = np.flatnonzero(np.diff(values) != 0.0) + 1
    return tuple(
        (start_frame + int(part[0]), start_frame + int(part[-1]),
         float(np.rad2deg(values[part[0]])))
        for part in np.split(np.arange(len(values)), cuts)
        if values[part[0]] != 0.0
    )  # fmt: skip


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


def decision_readout(evidence: dict[str, float | str]) -> str:
    """One line saying what the default (``apply="confident"``) does with an interval and which
    evidence decided (its ``evidence`` as :meth:`TwistInterval.to_json` writes it): for the
    findings list and the report, whatever the run applied.

    Examples: ``"default applied: the raw roll is 31° further outside the natural range than
    the corrected one (calibrated 0.14)"``; ``"default listed: smaller than this rig's natural
    upper arm roll (p99 16.5°)"``. Empty when nothing was recorded (the paper's method).
    """
    rule = str(evidence.get("rule", ""))
    if not rule:
        return ""
    verdict = f"default {evidence.get('default', 'listed')}"
    if "reason" in evidence:
        return f"{verdict}: {evidence['reason']}"
    values = {"calibrated": 0.0, "anatomy_deg": 0.0, **evidence, "verdict": verdict}
    template = _READOUTS.get(rule, "{verdict}: " + rule.replace("_", " "))
    return template.format(**values)
