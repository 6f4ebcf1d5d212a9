"""A shoot's reviewers' decisions as a prior on the calibrated probability of new intervals.

Accepted and rejected twist intervals are labels: the same joint of the same rig in the same
retarget breaks again and again across a shoot, and reviewers who accepted twelve intervals on
a calf have said what the next interval on that calf most likely is. :class:`ReviewerPrior`
holds, per (rig family, joint), the decided intervals of a shoot's other takes: each one's
calibrated probability ``p_i`` (as its run scored it, before any prior) and its label ``y_i``
(1 accepted, 0 rejected). From :data:`MIN_DECISIONS` decisions on a joint, the calibration's
intercept is refitted on them: ``b`` maximises

    sum_i [y_i log s(z_i + b) + (1 - y_i) log(1 - s(z_i + b))] - b^2 / (2 PRIOR_SCALE^2)

(``z_i = logit(p_i)``, ``s`` the logistic function; a Gaussian prior keeps ``b`` at 0 unless the
labels disagree with the calibration), clipped to ``±MAX_SHIFT``, and a new interval on that
joint is decided on ``p' = s(logit(p) + b)``. The refit, not a count of accepts and rejects,
is what keeps the prior from raising wrong intervals with right ones: an accepted interval the
calibration already scored 0.95 says nothing new and moves ``b`` hardly at all, while a rejected
one it scored 0.6 lowers it; a joint whose intervals were accepted at 0.2 raises the next 0.2.

``p'`` is what the ``calibrated`` rule compares with
:data:`mocapqa.twist.confidence.APPLY_THRESHOLD`; the hard evidence rules (minimum evidence,
natural roll, ends, anatomy against) are tried first and still decide
(:func:`mocapqa.twist.confidence.decide`). The prior is data: the pure layers take it as an
argument and never read a store; :meth:`ReviewerPrior.to_json` is what a run records, and
:attr:`ReviewerPrior.content_hash` names it.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.errors import InputError

__all__ = [
    "BANDWIDTH",
    "MAX_SHIFT",
    "MIN_DECISIONS",
    "PRIOR_SCALE",
    "JointLabels",
    "ReviewerPrior",
    "intercept_shift",
    "label_weights",
    "prior_probability",
]

MIN_DECISIONS = 3
"""Fewest decisions on a (rig family, joint), counted by their weight for the new interval
(:func:`label_weights`), from which the prior moves its probability: one or two decisions say
little and could be a reviewer's slip."""
MAX_SHIFT = 3.0
"""Largest move of the log-odds either way (a factor of about 20 on the odds): the reviewers
can bring an interval the calibration scores 0.1 to about 0.7, never a 0.001 one to 0.5."""
PRIOR_SCALE = 1.5
"""Standard deviation of the Gaussian prior on the refitted intercept, in log-odds: a handful
of labels that agree with the calibration leave it where it is; a dozen that all disagree move
it by about two."""
BANDWIDTH = 1.0
"""Standard deviation, in log-odds, of the Gaussian that weighs each decided interval by how
close its calibrated probability is to the new interval's (:func:`label_weights`): a decision
on an interval scored 0.99 says little about one scored 0.4."""
_COUNTED = 0.1
"""Decided intervals of at least this weight are the ones a readout counts."""
_EDGE = 1e-3
"""Probabilities are clipped to [_EDGE, 1 - _EDGE] before the log-odds: runs record them to
three decimals, so a recorded 0.000 is anything under 0.0005."""
_NEWTON_STEPS = 25
"""Newton steps of the one-parameter refit (the objective is concave; it converges in a few)."""


def _logit(probability: FloatArray) -> FloatArray:
    p = np.clip(np.asarray(probability, dtype=np.float64), _EDGE, 1.0 - _EDGE)
    result: FloatArray = np.log(p / (1.0 - p))
    return result


@dataclass(frozen=True, slots=True)
class JointLabels:
    """The decisions of a shoot's reviewers on one joint of one rig family.

    Parameters
    ----------
    rig : str
        Rig family (:func:`mocapqa.limits.rig.rig_family`).
    joint : str
        The interval's joint (its chain's parent joint name).
    probabilities : tuple of float
        The calibrated probability of each decided interval, as its run scored it, in [0, 1].
    accepted : tuple of bool
        Whether each interval's newest decision is accept (else reject).
    """

    rig: str
    joint: str
    probabilities: tuple[float, ...]
    accepted: tuple[bool, ...]

    @property
    def n_accepted(self) -> int:
        """Accepted intervals."""
        return sum(self.accepted)

    @property
    def n_rejected(self) -> int:
        """Rejected intervals."""
        return len(self.accepted) - sum(self.accepted)


def intercept_shift(
    probabilities: FloatArray,
    accepted: FloatArray,
    scale: float,
    max_shift: float,
    weights: FloatArray | None = None,
) -> float:
    """The MAP intercept ``b`` of the labels ``accepted`` on the log-odds of
    ``probabilities`` (module docstring), each label counted with its weight, clipped to
    ``±max_shift``.

    Parameters
    ----------
    probabilities : ndarray, shape (N,)
        Calibrated probabilities of the decided intervals, in [0, 1].
    accepted : ndarray, shape (N,)
        1 for an accepted interval, 0 for a rejected one.
    scale : float
        Standard deviation of the Gaussian prior on ``b``, log-odds.
    max_shift : float
        Largest ``|b|``, log-odds.
    weights : ndarray, shape (N,), optional
        Weight of each label in [0, 1] (1 each when None).

    Returns
    -------
    float
        ``b``, log-odds (0 for no labels).
    """
    z = _logit(np.asarray(probabilities, dtype=np.float64))
    y = np.asarray(accepted, dtype=np.float64)
    w = np.ones_like(z) if weights is None else np.asarray(weights, dtype=np.float64)
    b = 0.0
    for _ in range(_NEWTON_STEPS):
        s = 1.0 / (1.0 + np.exp(-(z + b)))
        gradient = float(np.sum(w * (y - s))) - b / scale**2
        curvature = float(np.sum(w * s * (1.0 - s))) + 1.0 / scale**2
        step = gradient / curvature
        b += step
        if abs(step) < 1e-9:
            break
    return float(np.clip(b, -max_shift, max_shift))


def label_weights(probability: float, probabilities: FloatArray, bandwidth: float) -> FloatArray:
    """How much each decided interval says about a new one of calibrated probability
    ``probability``: a Gaussian of the distance in log-odds.

    Parameters
    ----------
    probability : float
        The new interval's calibrated probability.
    probabilities : ndarray, shape (N,)
        The decided intervals' calibrated probabilities.
    bandwidth : float
        Standard deviation of the Gaussian, log-odds.

    Returns
    -------
    ndarray, shape (N,)
        Weights in (0, 1]; 1 for a decided interval scored exactly as the new one.
    """
    distance = _logit(np.asarray(probabilities, dtype=np.float64)) - _logit(
        np.asarray(probability, dtype=np.float64)
    )
    result: FloatArray = np.exp(-0.5 * (distance / bandwidth) ** 2)
    return result


def prior_probability(probability: FloatArray, shift: FloatArray) -> FloatArray:
    """The probability ``p`` moved by ``shift`` in log-odds; exactly ``p`` where ``shift`` is 0.

    Parameters
    ----------
    probability, shift : ndarray, shape (N,)

    Returns
    -------
    ndarray, shape (N,)
    """
    moved = 1.0 / (1.0 + np.exp(-(_logit(probability) + shift)))
    result: FloatArray = np.where(shift == 0.0, probability, moved)
    return result


@dataclass(frozen=True, slots=True)
class ReviewerPrior:
    """A shoot's reviewers' decisions per (rig family, joint), as a run uses them.

    Parameters
    ----------
    shoot : str
        The shoot the labels come from (its id).
    labels : tuple of JointLabels
        Sorted by rig, then joint; one per (rig, joint).
    runs : tuple of str
        The decided runs the labels were read from (sorted), for the record.
    min_decisions : int
        :data:`MIN_DECISIONS` unless measuring others.
    max_shift : float
        :data:`MAX_SHIFT` unless measuring others.
    scale : float
        :data:`PRIOR_SCALE` unless measuring others.
    bandwidth : float
        :data:`BANDWIDTH` unless measuring others.
    """

    shoot: str
    labels: tuple[JointLabels, ...]
    runs: tuple[str, ...] = ()
    min_decisions: int = MIN_DECISIONS
    max_shift: float = MAX_SHIFT
    scale: float = PRIOR_SCALE
    bandwidth: float = BANDWIDTH

    @classmethod
    def from_decisions(
        cls,
        shoot: str,
        decisions: Iterable[tuple[str, str, float, str]],
        runs: Iterable[str] = (),
        **settings: Any,
    ) -> ReviewerPrior:
        """The prior of ``(rig, joint, probability, decision)`` tuples (decision ``"accept"``
        or ``"reject"``; others are not labels and are skipped); ``settings`` are
        ``min_decisions``, ``max_shift``, ``scale`` and ``bandwidth``."""
        grouped: dict[tuple[str, str], list[tuple[float, bool]]] = {}
        for rig, joint, probability, decision in decisions:
            if decision in ("accept", "reject"):
                grouped.setdefault((rig, joint), []).append(
                    (float(probability), decision == "accept")
                )
        labels = tuple(
            JointLabels(r, j, tuple(p for p, _ in pairs), tuple(a for _, a in pairs))
            for (r, j), pairs in sorted(grouped.items())
        )
        return cls(shoot, labels, tuple(sorted(set(runs))), **settings)

    def shift(self, rig: str, joint: str, probability: float) -> tuple[float, int, int]:
        """The log-odds shift of a new interval of calibrated probability ``probability`` on
        ``joint`` of rig family ``rig``, refitted on that joint's labels weighted by
        :func:`label_weights`, with the accepted and rejected decisions that weigh in it
        (weight at least 0.1). ``(0.0, 0, 0)`` unless the weights sum to
        :attr:`min_decisions`: the reviewers must have decided that many intervals scored
        like this one."""
        found = [x for x in self.labels if x.rig == rig and x.joint == joint]
        if not found:
            return 0.0, 0, 0
        probabilities = np.array(found[0].probabilities, dtype=np.float64)
        accepted = np.array(found[0].accepted, dtype=np.float64)
        weights = label_weights(probability, probabilities, self.bandwidth)
        if weights.sum() < self.min_decisions:
            return 0.0, 0, 0
        b = intercept_shift(probabilities, accepted, self.scale, self.max_shift, weights)
        counted = weights >= _COUNTED
        return b, int(np.sum(counted & (accepted == 1))), int(np.sum(counted & (accepted == 0)))

    def adjust(
        self, probability: FloatArray, rig: str, joints: Sequence[str]
    ) -> tuple[FloatArray, IntArray, IntArray]:
        """The calibrated probability of intervals on ``joints`` of rig family ``rig`` after
        the prior, shape (N,), with the accepted and rejected decisions that moved each
        (:meth:`shift`)."""
        rows = [self.shift(rig, j, float(p)) for j, p in zip(joints, probability, strict=True)]
        shift = np.array([r[0] for r in rows], dtype=np.float64)
        counts = np.array([r[1:] for r in rows], dtype=np.intp).reshape(len(joints), 2)
        return prior_probability(probability, shift), counts[:, 0], counts[:, 1]

    @property
    def n_accepted(self) -> int:
        """Accepted intervals over every joint."""
        return sum(x.n_accepted for x in self.labels)

    @property
    def n_rejected(self) -> int:
        """Rejected intervals over every joint."""
        return sum(x.n_rejected for x in self.labels)

    def to_json(self) -> dict[str, Any]:
        """The prior as a JSON-ready dict (what a run records): per joint, each decided
        interval's probability (6 decimals) and whether it was accepted."""
        return {
            "shoot": self.shoot,
            "rule": (
                "logit(p') = logit(p) + b; b the intercept refitted on the joint's decided "
                "intervals weighted by exp(-(logit p_i - logit p)^2 / (2 bandwidth^2)), "
                "Gaussian prior of sd scale, clipped to max_shift"
            ),
            "min_decisions": self.min_decisions,
            "max_shift": self.max_shift,
            "scale": self.scale,
            "bandwidth": self.bandwidth,
            "labels": [
                [x.rig, x.joint, [[round(p, 6), int(a)] for p, a in zip(
                    x.probabilities, x.accepted, strict=True
                )]]
                for x in self.labels
            ],
            "runs": list(self.runs),
        }  # fmt: skip

    @property
    def content_hash(self) -> str:
        """SHA-256 of :meth:`to_json` as canonical JSON (sorted keys, no spaces)."""
        text = json.dumps(self.to_json(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def summary(self) -> dict[str, Any]:
        """What a run's report says of the prior it used: its hash and counts."""
        return {
            "hash": self.content_hash,
            "shoot": self.shoot,
            "accepted": self.n_accepted,
            "rejected": self.n_rejected,
            "joints": len(self.labels),
            "runs": len(self.runs),
        }

    @classmethod
    def from_json(cls, data: dict[str, Any], source: str = "prior") -> ReviewerPrior:
        """The prior from :meth:`to_json`'s dict.

        Raises
        ------
        InputError
            When a field is missing or malformed.
        """
        try:
            labels = tuple(
                JointLabels(
                    str(r), str(j),
                    tuple(float(p) for p, _ in pairs), tuple(bool(a) for _, a in pairs),
                )
                for r, j, pairs in data["labels"]
            )  # fmt: skip
            return cls(
                str(data["shoot"]),
                labels,
                tuple(str(r) for r in data.get("runs", [])),
                int(data["min_decisions"]),
                float(data["max_shift"]),
                float(data["scale"]),
                float(data["bandwidth"]),
            )
        except (KeyError, TypeError, ValueError) as error:
            raise InputError(f"Expected a reviewer prior in {source}, got {error!r}") from error
