"""Anatomy evidence (joint limits) in the default apply choice."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.io.bvh import read_bvh
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.anatomy import AnatomyEvidence
from mocapqa.twist.choice import choose_intervals
from mocapqa.twist.confidence import (
    ANATOMY_MAX_S,
    ANATOMY_MIN_DEG,
    MIN_LEVEL_DEG,
    decide,
)
from mocapqa.twist.intervals import FEATURES
from mocapqa.twist.repetition import family_counts


def _features(level_deg: float = 40.0, mismatch: float = 0.1, length_s: float = 0.05) -> tuple:
    values = dict.fromkeys(FEATURES, 0.0)
    values.update(
        log_jump_ratio=5.0,
        mismatch=mismatch,
        log_length_s=float(np.log(length_s)),
        log_level_deg=float(np.log(level_deg)),
    )
    return tuple(values[name] for name in FEATURES)


def _evidence(
    raw: float, fixed: float, outward: float = -10.0, child: float = 0.0
) -> AnatomyEvidence:
    one = np.ones(1)
    return AnatomyEvidence(one * raw, one * fixed, one * outward, one * 0.0, one * child,
                           np.ones(1, dtype=bool))  # fmt: skip


def test_a_twist_brought_back_inside_its_range_is_applied_at_a_low_probability() -> None:
    p = np.array([0.1])
    applied, rules = decide(p, [_features()], _evidence(ANATOMY_MIN_DEG + 1.0, 0.0))
    assert applied.tolist() == [True]
    assert rules == ("anatomy",)
    # Without the anatomy evidence the calibrated probability decides.
    applied, rules = decide(p, [_features()], None)
    assert applied.tolist() == [False]
    assert rules == ("calibrated",)


@pytest.mark.parametrize(
    ("evidence", "features"),
    [
        (_evidence(ANATOMY_MIN_DEG - 1.0, 0.0), _features()),  # not far enough out
        (_evidence(ANATOMY_MIN_DEG + 1.0, 2.0), _features()),  # the fix is still outside
        (_evidence(ANATOMY_MIN_DEG + 1.0, 0.0, outward=ANATOMY_MIN_DEG), _features()),
        (_evidence(ANATOMY_MIN_DEG + 1.0, 0.0), _features(mismatch=0.8)),  # child moves
        (_evidence(ANATOMY_MIN_DEG + 1.0, 0.0), _features(length_s=2 * ANATOMY_MAX_S)),
        (_evidence(ANATOMY_MIN_DEG + 1.0, 0.0), _features(level_deg=MIN_LEVEL_DEG / 2)),
    ],
)
def test_the_anatomy_rule_needs_all_of_its_evidence(
    evidence: AnatomyEvidence, features: tuple
) -> None:
    applied, _ = decide(np.array([0.1]), [features], evidence)
    assert applied.tolist() == [False]


def test_a_correction_that_pushes_a_natural_twist_out_is_not_applied_however_probable() -> None:
    applied, rules = decide(np.array([0.99]), [_features()], _evidence(0.0, ANATOMY_MIN_DEG))
    assert applied.tolist() == [False]
    assert rules == ("anatomy_against",)
    applied, rules = decide(
        np.array([0.99]), [_features()], _evidence(0.0, 0.0, child=ANATOMY_MIN_DEG)
    )
    assert applied.tolist() == [False]
    assert rules == ("anatomy_against",)


def test_the_paper_method_still_applies_every_interval() -> None:
    applied, rules = decide(np.array([1.0]), [()], _evidence(0.0, 90.0))
    assert applied.tolist() == [True]
    assert rules == ("uncalibrated",)


def test_no_interval_no_work() -> None:
    offsets, intervals = choose_intervals([], np.zeros((3, 0)), [], [], "confident", True)
    assert intervals == []
    assert offsets.shape == (3, 0)


def test_a_real_right_knee_flip_of_005_05_is_applied_by_default(corpus_dir: Path) -> None:
    """Evaluation take: no parameter is chosen on it; this pins the behaviour."""
    motion = read_bvh(corpus_dir / "bvh/cmu/iclone/005_05.bvh")
    analysis = analyze_twist(motion)
    # The calf rolls 42°, 21°, 47° and 63° over frames 316–319 while the foot counter-rotates;
    # the knee's twist range of the limits model ends about 41° from its middle.
    (flip,) = [
        i for i in analysis.intervals
        if i.joint == "CC_Base_R_Calf" and i.start_frame <= 319 <= i.end_frame
    ]  # fmt: skip
    record = flip.to_json()["evidence"]
    assert flip.applied
    assert record["rule"] == "anatomy"
    assert record["anatomy_deg"] >= ANATOMY_MIN_DEG
    assert 0.0 <= record["calibrated"] <= 1.0
    # Every interval of the robust method says which evidence decided.
    assert all("rule" in i.to_json()["evidence"] for i in analysis.intervals)


@pytest.mark.parametrize(
    "path",
    [
        "bvh/bandai/dataset-1_kick_normal_001.bvh",
        "bvh/bandai/dataset-1_guide_angry_001.bvh",
        "bvh/bandai/dataset-2_run_normal_001.bvh",
        "bvh/cmu/iclone/005_11.bvh",
        "bvh/cmu/iclone/002_10.bvh",
    ],
)
def test_clean_takes_natural_roll_is_not_pushed_over_by_the_anatomy_rule(
    corpus_dir: Path, path: str
) -> None:
    # The three Bandai takes are the corpus' clean takes with an interval found (an upper arm
    # rolling fast); the two Character Creator takes roll their arms past the other rigs' range.
    analysis = analyze_twist(read_bvh(corpus_dir / path))
    assert not any(i.applied for i in analysis.intervals)
    assert all(i.to_json()["evidence"]["rule"] != "anatomy" for i in analysis.intervals)


def test_a_family_counts_the_other_strong_intervals_of_a_chain() -> None:
    chains = np.array([0, 0, 0, 1, 1])
    strong = np.array([True, True, False, True, False])
    assert family_counts(chains, strong).tolist() == [1, 1, 2, 0, 1]
    assert family_counts(np.zeros(0, dtype=int), np.zeros(0, dtype=bool)).tolist() == []


def test_repetition_supports_a_weak_interval_only_beside_strong_ones_on_its_chain() -> None:
    p = np.array([0.95, 0.97, 0.2, 0.2])
    features = [_features()] * 4
    applied, rules = decide(p, features, None, chains=[0, 0, 0, 1], min_family=2)
    assert applied.tolist() == [True, True, True, False]
    assert rules[2] == "repetition"
    assert rules[3] == "calibrated"
    # Never for a long interval.
    long = [_features(), _features(), _features(length_s=2 * ANATOMY_MAX_S), _features()]
    applied, _ = decide(p, long, None, chains=[0, 0, 0, 1], min_family=2)
    assert applied.tolist() == [True, True, False, False]
