"""Calibrated confidence of a twist interval: the probability that applying it is right.

Conventions
-----------
The model is a logistic regression on the features of
:data:`mocapqa.twist.intervals.FEATURES`, standardised with the means and scales stored beside
the coefficients in ``data/twist/calibration.json``, followed by an isotonic map of its score
fitted on out-of-fold scores (folds by take), which corrects the logistic model where its
linear form is over- or under-confident (bursts in the middle range). That file is written by
``mocapqa bench twist --fit-calibration`` from injected errors on the *fit* takes of the corpus
only (never the held-out takes and never ``005_05``, the take with real errors). An interval is
labelled right when applying it alone removes at least 80 % of the twist error on its frames
and raises no frame's error by more than 1°.

``APPLY_THRESHOLD`` is the probability from which ``apply="confident"`` applies an interval, and
:func:`has_evidence` the minimum-evidence rule it also requires: the interval's largest level
must be at least ``MIN_LEVEL_DEG``, so a small interval inside the natural roll noise is reported
but not applied, and the roll outside the interval must not contradict its jumps by more than
``MAX_DISAGREEMENT`` times the level (then nothing outside the events shows a level shift).

:func:`decide` adds evidence whose meaning does not depend on the injected errors the
calibration was fitted on (``docs/twist.md``, Confidence and applying): the joint-limits model
(:mod:`mocapqa.twist.anatomy`). An interval whose raw twist lies at least ``ANATOMY_MIN_DEG``
beyond the natural range while the correction brings it inside, whose child the correction does
not push out of its range, and whose events counter-rotate within ``ANATOMY_MAX_MISMATCH``, is
applied whatever its calibrated probability (rule ``"anatomy"``), unless the correction moves
the twist of some frame ``ANATOMY_MIN_DEG`` or more toward the edge of the range (a level
removed from natural frames) or the interval lasts longer than ``ANATOMY_MAX_S``; an interval
whose correction moves a twist from inside the range to ``ANATOMY_MIN_DEG`` or more beyond it
(on the parent or the child) is not (rule ``"anatomy_against"``). A repetition rule (the other
strong intervals of the interval's chain, :mod:`mocapqa.twist.repetition`) can be asked for
with ``min_family``; it is off by default (``REPETITION_MIN_FAMILY`` = 0, see the docs).

The ``probability`` :func:`decide` compares with :data:`APPLY_THRESHOLD` is the calibrated one,
or, in a run of a shoot whose reviewers decided intervals on the same joint, the calibrated one
moved by their decisions (:mod:`mocapqa.twist.reviewer_prior`, applied by
:func:`mocapqa.twist.choice.choose_intervals`): the rules tried before the ``calibrated`` one
do not read it, so no decision overrides them.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError
from mocapqa.twist.anatomy import AnatomyEvidence
from mocapqa.twist.intervals import FEATURES
from mocapqa.twist.repetition import family_counts
from mocapqa.twist.shipped import shipped_json

__all__ = [
    "ANATOMY_MAX_MISMATCH",
    "ANATOMY_MAX_S",
    "ANATOMY_MIN_DEG",
    "APPLY_THRESHOLD",
    "CALIBRATION_FILE",
    "END_MAX_MISMATCH",
    "END_MIN_LEVEL_DEG",
    "MAX_DISAGREEMENT",
    "MIN_LEVEL_DEG",
    "REPETITION_MIN_FAMILY",
    "REPETITION_STRONG_P",
    "RULES",
    "Calibration",
    "decide",
    "default_calibration",
    "fit_calibration",
    "has_evidence",
]

APPLY_THRESHOLD = 0.5
"""Smallest calibrated probability at which ``apply="confident"`` applies an interval."""
MIN_LEVEL_DEG = 5.0
"""Smallest largest level, degrees, of an interval that ``apply="confident"`` applies: the
smallest offset of the injection protocol (no interval on the fit takes is smaller)."""
MAX_DISAGREEMENT = 1.5
"""Largest disagreement between the level measured from the roll outside an interval and the
level accumulated from its jumps, relative to the latter (the ``disagreement`` feature), of an
interval that ``apply="confident"`` applies. Chosen on the injected takes as the smallest of
1, 1.25, 1.5 and 1.75 that keeps every right interval: by each pair of rigs, 1.5 each time."""
ANATOMY_MIN_DEG = 15.0
"""Degrees beyond the natural twist range (joint-limits model) that count as anatomical evidence:
a raw twist this far outside, brought inside by the correction, applies an interval; a twist
inside pushed this far outside blocks it. Chosen on the fit takes' injected errors (docs)."""
ANATOMY_MAX_MISMATCH = 0.5
"""Largest counter-rotation mismatch ratio (the ``mismatch`` feature: how far the child's world
orientation moves at the interval's events, relative to the jump) of an interval the anatomy
rule applies: the events' own consistency rule, so the child keeps its world orientation."""
ANATOMY_MAX_S = 0.25
"""Longest interval, seconds, the anatomy rule applies: over a longer one most frames sit inside
the range, so frames outside it say that an error is there, not that the whole interval's
levels belong where they were put. Chosen on the fit takes' injected errors (docs)."""
END_MIN_LEVEL_DEG = 20.0
"""Smallest level, degrees, at which ``apply="confident"`` applies a one-sided interval (one that
runs to an end of the take) whose event's counter-rotation is not exact (mismatch above
:data:`END_MAX_MISMATCH`): the top of the small-offset range (5–20°), which natural roll steps
reach. One event carries no closure check, so such an interval is reported, not applied.
Chosen on the fit takes' injections (docs)."""
END_MAX_MISMATCH = 0.05
"""Largest counter-rotation mismatch ratio of the one event at which a one-sided interval under
:data:`END_MIN_LEVEL_DEG` is applied by ``apply="confident"`` (a tenth of the events'
``consistency``). Chosen on the fit takes' injections (docs)."""
REPETITION_MIN_FAMILY = 0
"""Other strong intervals on an interval's chain that apply it (``"repetition"``); 0: the
repetition rule is off (measured on the fit takes, docs)."""
REPETITION_STRONG_P = 0.9
"""Calibrated probability from which an interval counts as strong for the repetition rule."""
RULES = (
    "calibrated",
    "anatomy",
    "anatomy_against",
    "repetition",
    "min_evidence",
    "natural_roll",
    "end_evidence",
    "uncalibrated",
)
"""Which evidence decided an interval under ``apply="confident"`` (:func:`decide`).

In order: no calibrated features (the paper's method) applies (``"uncalibrated"``); failing
:func:`has_evidence` does not (``"min_evidence"``); an interval whose largest level is under
the natural roll level of its rig's segment (``natural_deg``,
:mod:`mocapqa.twist.natural_roll`) does not, whatever else speaks for it (``"natural_roll"``):
it cannot be told from natural roll by its size; a one-sided interval (``sides``: "head" or
"tail") whose level is under :data:`END_MIN_LEVEL_DEG` and whose event's mismatch ratio is over
:data:`END_MAX_MISMATCH` does not (``"end_evidence"``); a correction that moves the parent's
twist or the child's rotation from inside its range to ``min_deg`` or more beyond it does not
(``"anatomy_against"``); a raw twist ``min_deg`` or more beyond the range that the correction
brings inside, moving no frame's twist ``min_deg`` or more toward the range's edge, with the
child not pushed ``min_deg`` further out, a mismatch ratio of at most ``max_mismatch`` and a
duration of at most ``max_s``, applies (``"anatomy"``); with ``min_family`` > 0, an interval as
short and as well counter-rotated with at least ``min_family`` other strong intervals on its
chain (probability ≥ ``strong_p`` or the anatomy rule,
:func:`mocapqa.twist.repetition.family_counts`) applies (``"repetition"``); otherwise the
calibrated probability (after a shoot's reviewer prior, when the run has one) decides against
:data:`APPLY_THRESHOLD` (``"calibrated"``).
"""
CALIBRATION_FILE = "calibration.json"
"""Name of the stored calibration in the package's ``data/twist`` folder."""


@dataclass(frozen=True, slots=True)
class Calibration:
    """A logistic model on standardised interval features.

    Parameters
    ----------
    features : tuple of str
        Feature names, in :data:`mocapqa.twist.intervals.FEATURES` order.
    mean, scale : ndarray, shape (K,)
        Standardisation of each feature.
    coef : ndarray, shape (K,)
        Logistic coefficients.
    intercept : float
    fitted_on : str
        What the model was fitted on (written to the docs and the bench).
    isotonic_x, isotonic_y : ndarray, shape (M,)
        Increasing logistic scores and the calibrated probability at each (linear in between,
        clipped outside); empty for the logistic score itself.
    """

    features: tuple[str, ...]
    mean: FloatArray
    scale: FloatArray
    coef: FloatArray
    intercept: float
    fitted_on: str
    isotonic_x: FloatArray = field(default_factory=lambda: np.zeros(0))
    isotonic_y: FloatArray = field(default_factory=lambda: np.zeros(0))

    def score(self, features: FloatArray) -> FloatArray:
        """The logistic score of each interval, shape (N,) from features (N, K)."""
        x = (np.asarray(features, dtype=np.float64) - self.mean) / self.scale
        result: FloatArray = 1.0 / (1.0 + np.exp(-(x @ self.coef + self.intercept)))
        return result

    def probability(self, features: FloatArray) -> FloatArray:
        """Probability that each interval is right, shape (N,) from features (N, K)."""
        score = self.score(features)
        if len(self.isotonic_x) == 0:
            return score
        result: FloatArray = np.interp(score, self.isotonic_x, self.isotonic_y)
        return result

    def to_json(self) -> dict[str, Any]:
        """The model as a JSON-ready dict."""
        return {
            "features": list(self.features),
            "mean": self.mean.tolist(),
            "scale": self.scale.tolist(),
            "coef": self.coef.tolist(),
            "intercept": self.intercept,
            "fitted_on": self.fitted_on,
            "isotonic_x": self.isotonic_x.tolist(),
            "isotonic_y": self.isotonic_y.tolist(),
        }

    @classmethod
    def from_json(cls, data: dict[str, Any], source: str = "calibration") -> Calibration:
        """The model from :meth:`to_json`'s dict.

        Raises
        ------
        InputError
            When the features differ from :data:`FEATURES` or a field is missing.
        """
        try:
            names = tuple(str(n) for n in data["features"])
            arrays = [np.asarray(data[k], dtype=np.float64) for k in ("mean", "scale", "coef")]
            intercept = float(data["intercept"])
            fitted_on = str(data.get("fitted_on", ""))
            isotonic = [np.asarray(data.get(k, []), dtype=np.float64)
                        for k in ("isotonic_x", "isotonic_y")]  # fmt: skip
        except (KeyError, TypeError, ValueError) as error:
            raise InputError(f"Expected a twist calibration in {source}, got {error!r}") from error
        if names != FEATURES or any(a.shape != (len(FEATURES),) for a in arrays):
            raise InputError(
                f"Expected calibration features {list(FEATURES)} in {source}, got {list(names)}"
            )
        if isotonic[0].shape != isotonic[1].shape or isotonic[0].ndim != 1:
            raise InputError(f"Expected isotonic_x and isotonic_y of one length in {source}")
        return cls(names, arrays[0], arrays[1], arrays[2], intercept, fitted_on, *isotonic)


def has_evidence(features: Sequence[float]) -> bool:
    """Whether an interval's largest level reaches :data:`MIN_LEVEL_DEG` and the roll outside it
    disagrees with its jumps by less than :data:`MAX_DISAGREEMENT`.

    Parameters
    ----------
    features : sequence of float
        The interval's features (:data:`mocapqa.twist.intervals.FEATURES`); empty (no
        calibrated features, the paper's method) counts as evidence.
    """
    if not features:
        return True
    large = features[FEATURES.index("log_level_deg")] >= np.log(MIN_LEVEL_DEG)
    return bool(large and features[FEATURES.index("disagreement")] < MAX_DISAGREEMENT)


def decide(
    probability: FloatArray,
    features: Sequence[Sequence[float]],
    anatomy: AnatomyEvidence | None,
    min_deg: float = ANATOMY_MIN_DEG,
    max_mismatch: float = ANATOMY_MAX_MISMATCH,
    max_s: float = ANATOMY_MAX_S,
    chains: Sequence[int] | None = None,
    min_family: int = REPETITION_MIN_FAMILY,
    strong_p: float = REPETITION_STRONG_P,
    sides: Sequence[str] | None = None,
    natural_deg: Sequence[float] | None = None,
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Whether ``apply="confident"`` applies each interval, and which evidence decided.

    The rules, in the order they are tried (the first that holds decides), are described at
    :data:`RULES`.

    Parameters
    ----------
    probability : ndarray, shape (N,)
        Calibrated probabilities (moved by a reviewer prior, when the run has one).
    features : sequence of sequence of float, length N
        Each interval's :data:`FEATURES` (empty for the paper's method).
    anatomy : AnatomyEvidence or None
        From :func:`mocapqa.twist.anatomy.anatomy_evidence`; None: no anatomy evidence.
    min_deg, max_mismatch, max_s : float
        :data:`ANATOMY_MIN_DEG`, :data:`ANATOMY_MAX_MISMATCH` and :data:`ANATOMY_MAX_S` unless
        measuring others.
    chains : sequence of int, optional
        Chain of each interval (for the repetition evidence; none without it).
    min_family : int
        Other strong intervals on the chain that support an interval; 0: no repetition rule.
    strong_p : float
        Calibrated probability from which an interval counts as strong.
    sides : sequence of str, optional
        Each interval's side ("", "head" or "tail"); None: no one-sided interval.
    natural_deg : sequence of float, optional
        Natural roll level of each interval's rig segment, degrees (0: none stored, the
        :data:`MIN_LEVEL_DEG` of :func:`has_evidence` holds); None: no natural roll rule.

    Returns
    -------
    applied : ndarray of bool, shape (N,)
    rules : tuple of str, length N
        One of :data:`RULES` per interval.
    """
    n = len(features)
    p = np.asarray(probability, dtype=np.float64).reshape(n)
    if anatomy is None:
        anatomy = AnatomyEvidence.empty(n)
    calibrated = np.array([len(f) > 0 for f in features], dtype=bool)
    evidence = np.array([has_evidence(f) for f in features], dtype=bool)
    weak_end = _weak_ends(features, sides)
    natural = np.zeros(n) if natural_deg is None else np.asarray(natural_deg, dtype=np.float64)
    level, mismatch, short = _feature_arrays(features, max_s)
    rolled = calibrated & evidence & (level < natural.reshape(n))
    against, brought = _anatomy_rules(anatomy, min_deg)
    support = anatomy.checked & brought & short & (mismatch <= max_mismatch) & ~against
    family = (
        _family(chains, min_family, calibrated & evidence & ~against, support, p >= strong_p)
        & short & (mismatch <= max_mismatch) & (p < APPLY_THRESHOLD)
    )  # fmt: skip
    applied = np.where(
        ~calibrated,
        True,
        evidence & ~rolled & ~weak_end & ~against & (support | family | (p >= APPLY_THRESHOLD)),
    )
    rules = np.select(
        [~calibrated, ~evidence, rolled, weak_end, against, support, family],
        ["uncalibrated", "min_evidence", "natural_roll", "end_evidence", "anatomy_against",
         "anatomy", "repetition"],
        "calibrated",
    )  # fmt: skip
    return applied.astype(bool), tuple(str(r) for r in rules)


def _family(
    chains: Sequence[int] | None,
    min_family: int,
    eligible: BoolArray,
    support: BoolArray,
    strong_p: BoolArray,
) -> BoolArray:
    """Whether each ``eligible`` interval not applied by the anatomy rule has at least
    ``min_family`` other strong intervals (``support`` or ``strong_p``, eligible) on its chain,
    shape (N,); none without ``chains`` or with ``min_family`` 0."""
    if chains is None or min_family <= 0:
        return np.zeros(len(eligible), dtype=bool)
    strong = eligible & (support | strong_p)
    others = family_counts(np.asarray(chains, dtype=np.intp), strong)
    family: BoolArray = (others >= min_family) & eligible & ~support
    return family


def _feature_arrays(
    features: Sequence[Sequence[float]], max_s: float
) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Each interval's largest level (degrees) and mismatch ratio (inf without features), and
    whether it lasts at most ``max_s`` seconds, each shape (N,)."""
    level = np.array(
        [np.exp(f[FEATURES.index("log_level_deg")]) if f else np.inf for f in features],
        dtype=np.float64,
    )
    mismatch = np.array(
        [f[FEATURES.index("mismatch")] if f else np.inf for f in features], dtype=np.float64
    )
    short = np.array(
        [bool(f) and f[FEATURES.index("log_length_s")] <= np.log(max_s) for f in features],
        dtype=bool,
    )
    return level, mismatch, short


def _weak_ends(features: Sequence[Sequence[float]], sides: Sequence[str] | None) -> BoolArray:
    """Whether each interval is one-sided with a level under :data:`END_MIN_LEVEL_DEG` and a
    mismatch ratio over :data:`END_MAX_MISMATCH`, shape (N,) of bool."""
    n = len(features)
    one_sided = np.array(
        [False] * n if sides is None else [bool(side) for side in sides], dtype=bool
    )
    weak: BoolArray = one_sided & np.array(
        [
            bool(f)
            and f[FEATURES.index("log_level_deg")] < np.log(END_MIN_LEVEL_DEG)
            and f[FEATURES.index("mismatch")] > END_MAX_MISMATCH
            for f in features
        ],
        dtype=bool,
    )
    return weak


def _anatomy_rules(anatomy: AnatomyEvidence, min_deg: float) -> tuple[BoolArray, BoolArray]:
    """Per interval, shape (N,) of bool each: whether the correction pushes the parent's twist
    or the child's rotation from inside its range to ``min_deg`` or more beyond it (checked
    intervals only), and whether it brings a raw twist ``min_deg`` or more beyond the range
    inside, moving no frame ``min_deg`` toward the edge and the child not ``min_deg`` further
    out."""
    raw, fixed = anatomy.raw_deg, anatomy.fixed_deg
    child_raw, child_fixed = anatomy.child_raw_deg, anatomy.child_fixed_deg
    pushed = ((raw <= 0.0) & (fixed >= min_deg)) | ((child_raw <= 0.0) & (child_fixed >= min_deg))
    brought = (
        (raw >= min_deg)
        & (fixed <= 0.0)
        & (anatomy.outward_deg < min_deg)
        & (child_fixed - child_raw < min_deg)
    )
    against: BoolArray = anatomy.checked & pushed
    return against, brought


@cache
def default_calibration() -> Calibration:
    """The shipped calibration (``mocapqa/data/twist/calibration.json``), read once."""
    return Calibration.from_json(*shipped_json(CALIBRATION_FILE))


def fit_calibration(
    features: FloatArray,
    labels: Sequence[bool],
    fitted_on: str,
    path: Path | None = None,
    groups: Sequence[str] | None = None,
) -> Calibration:
    """Fit the logistic model (scikit-learn, L2, C = 1), its isotonic map, optionally write it.

    The isotonic map is fitted on the logistic scores of 5 folds (by ``groups``, e.g. takes,
    when given), each scored by a model fitted on the other folds.

    Parameters
    ----------
    features : ndarray, shape (N, K)
    labels : sequence of bool, length N
        Whether each interval was right.
    fitted_on : str
        Description of the data, stored with the model.
    path : Path, optional
        Where to write the JSON.
    groups : sequence of str, optional
        Group of each interval (its take), so that no fold scores a take it was fitted on.

    Returns
    -------
    Calibration

    Raises
    ------
    InputError
        With fewer than two classes among the labels.
    """
    from sklearn.isotonic import IsotonicRegression
    from sklearn.linear_model import LogisticRegression
    from sklearn.model_selection import GroupKFold

    x = np.asarray(features, dtype=np.float64)
    y = np.asarray(labels, dtype=bool)
    if len(set(y.tolist())) < 2:
        raise InputError("Expected right and wrong intervals to fit a calibration, got one class")
    mean = x.mean(axis=0)
    scale = np.where(x.std(axis=0) > 1e-9, x.std(axis=0), 1.0)
    z = (x - mean) / scale
    model = LogisticRegression(C=1.0, max_iter=1000).fit(z, y)
    fold_of = np.asarray(groups if groups is not None else np.arange(len(y)) % 5)
    scores = np.zeros(len(y))
    for fit_rows, score_rows in GroupKFold(n_splits=5).split(z, y, fold_of):
        if len(set(y[fit_rows].tolist())) < 2:
            scores[score_rows] = y[fit_rows].mean()
            continue
        fold = LogisticRegression(C=1.0, max_iter=1000).fit(z[fit_rows], y[fit_rows])
        scores[score_rows] = fold.predict_proba(z[score_rows])[:, 1]
    isotonic = IsotonicRegression(y_min=0.0, y_max=1.0, out_of_bounds="clip").fit(scores, y)
    calibration = Calibration(
        FEATURES, mean, scale, model.coef_[0].copy(), float(model.intercept_[0]), fitted_on,
        np.asarray(isotonic.X_thresholds_, dtype=np.float64),
        np.asarray(isotonic.y_thresholds_, dtype=np.float64),
    )  # fmt: skip
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(calibration.to_json(), indent=2) + "\n", encoding="utf-8")
    return calibration
