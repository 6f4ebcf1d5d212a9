"""Which detected twist intervals a refinement applies, and their report entries.

``apply`` is one of :data:`APPLY_CHOICES` or a set of interval ids. Ids number the intervals of
a take in chain, then frame order. ``confident`` applies intervals whose calibrated probability
is at least :data:`mocapqa.twist.confidence.APPLY_THRESHOLD` and that pass the minimum-evidence
rule :func:`mocapqa.twist.confidence.has_evidence`, or that the anatomy evidence supports, and
never those it contradicts (:func:`mocapqa.twist.confidence.decide`; methods without a
calibrated confidence apply all); an interval smaller than its rig segment's natural roll
(:mod:`mocapqa.twist.natural_roll`) is never applied by ``confident``. Each interval's
``evidence`` records which evidence decided, and why when it is the natural roll.
A shoot's reviewers' decisions (:class:`mocapqa.twist.reviewer_prior.ReviewerPrior`) move the
calibrated probability the ``calibrated`` rule compares; an interval whose probability they
moved records it (``reviewer_probability``, ``reviewer_accepted``, ``reviewer_rejected``) and
its readout says by how many decisions.
Each :class:`TwistInterval` lists its ``levels``: the stretches of constant offset, so the
refined take is exactly the raw one with the applied levels removed.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.errors import InputError, OptionError
from mocapqa.twist.anatomy import AnatomyEvidence
from mocapqa.twist.angles import ChainGeometry
from mocapqa.twist.confidence import decide
from mocapqa.twist.detect import DetectedInterval
from mocapqa.twist.readouts import decision_readout
from mocapqa.twist.reviewer_prior import ReviewerPrior

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
        (readable); with a reviewer prior that has labels on the interval's joint,
        ``reviewer_probability`` (the probability after the prior, which the ``calibrated``
        rule compares), ``reviewer_accepted`` and ``reviewer_rejected`` (the decisions that
        moved it). Empty for the paper's method.
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
    prior: ReviewerPrior | None = None,
    rig: str = "",
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
    prior : ReviewerPrior, optional
        A shoot's reviewers' decisions, moving the calibrated probability on their joints.
    rig : str
        The take's rig family (:func:`mocapqa.limits.rig.rig_family`), the prior's key.

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
    offsets, intervals = np.zeros_like(detected), list[TwistInterval]()
    probability = np.array([i.confidence for i in found], dtype=np.float64)
    features = [i.features if calibrated else () for i in found]
    joints = [names[geometries[i.chain].chain.parent] for i in found]
    reviewed = _reviewed(probability, features, prior, rig, joints)
    confident, rules = decide(
        reviewed[0], features, anatomy, chains=[i.chain for i in found],
        sides=[i.side for i in found], natural_deg=natural_deg,
    )  # fmt: skip
    for k, i in enumerate(found):
        applied = _is_applied(choice, k, bool(confident[k]))
        chain = geometries[i.chain].chain
        evidence: tuple[tuple[str, float | str], ...] = ()
        if features[k]:
            natural = 0.0 if natural_deg is None else float(natural_deg[k])
            evidence = _evidence(
                i, k, anatomy, natural, rules[k], bool(confident[k]), chain.segment
            )
            evidence = _with_reviewers(evidence, reviewed, k)
        rows = slice(i.start_frame, i.end_frame + 1)
        if applied:
            offsets[rows, i.chain] = detected[rows, i.chain]
        intervals.append(
            TwistInterval(
                joints[k], chain.side, chain.segment, i.start_frame, i.end_frame,
                float(np.rad2deg(i.offset_rad)), float(i.confidence), k, applied,
                _levels(detected[rows, i.chain], i.start_frame), evidence,
            )
        )  # fmt: skip
    return offsets, intervals


def _reviewed(
    probability: FloatArray,
    features: Sequence[Sequence[float]],
    prior: ReviewerPrior | None,
    rig: str,
    joints: Sequence[str],
) -> tuple[FloatArray, IntArray, IntArray]:
    """The probability each interval is decided on (after ``prior``, calibrated intervals
    only) and the accepted and rejected decisions that moved it, each shape (N,)."""
    n = len(joints)
    if prior is None:
        return probability, np.zeros(n, dtype=np.intp), np.zeros(n, dtype=np.intp)
    moved, accepted, rejected = prior.adjust(probability, rig, joints)
    calibrated = np.array([len(f) > 0 for f in features], dtype=bool)
    return (
        np.where(calibrated, moved, probability),
        np.where(calibrated, accepted, 0),
        np.where(calibrated, rejected, 0),
    )


def _with_reviewers(
    evidence: tuple[tuple[str, float | str], ...],
    reviewed: tuple[FloatArray, IntArray, IntArray],
    k: int,
) -> tuple[tuple[str, float | str], ...]:
    """``evidence`` with the probability after the reviewer prior and the decisions that moved
    it, when some did (inserted after ``calibrated``)."""
    probability, accepted, rejected = reviewed
    if accepted[k] + rejected[k] == 0:
        return evidence
    extra: tuple[tuple[str, float | str], ...] = (
        ("reviewer_probability", float(probability[k])),
        ("reviewer_accepted", float(accepted[k])),
        ("reviewer_rejected", float(rejected[k])),
    )
    return evidence[:1] + extra + evidence[1:]


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
    OptionError
        Naming ``apply``, for an interval id the take does not have.
    """
    if isinstance(choice, frozenset) and choice and max(choice) >= n_found:
        if not n_found:
            raise OptionError(
                "apply",
                f"Expected no interval ids on a take with no twist interval, got {sorted(choice)}",
            )
        raise OptionError(
            "apply", f"Expected interval ids 0 to {n_found - 1}, got {_shown(choice)}"
        )


def _shown(ids: frozenset[int], most: int = 20) -> str:
    """``ids`` sorted, the first ``most`` of them (a list of 10,000 ids is not a message)."""
    ordered = sorted(ids)
    more = f" and {len(ordered) - most:,} more" if len(ordered) > most else ""
    return f"{ordered[:most]}{more}"


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
