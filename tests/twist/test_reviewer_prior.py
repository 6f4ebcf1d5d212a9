"""The reviewer prior: its arithmetic, its record, and what it does to the default choice."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.limits.rig import rig_family
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.choice import decision_readout
from mocapqa.twist.confidence import APPLY_THRESHOLD
from mocapqa.twist.reviewer_prior import (
    MAX_SHIFT,
    MIN_DECISIONS,
    PRIOR_SCALE,
    ReviewerPrior,
    intercept_shift,
    prior_probability,
)


def _prior(
    accepted: int,
    rejected: int,
    joint: str = "RightLeg",
    rig: str = "cmu",
    probability: float = 0.2,
) -> ReviewerPrior:
    decisions = [(rig, joint, probability, "accept")] * accepted + [
        (rig, joint, probability, "reject")
    ] * rejected
    return ReviewerPrior.from_decisions("shoot-1", decisions, ["run-b", "run-a"])


def _map_intercept(p: np.ndarray, y: np.ndarray, scale: float) -> float:
    """The MAP intercept by brute force over a fine grid (what the Newton steps must find)."""
    z = np.log(p / (1.0 - p))
    grid = np.linspace(-6.0, 6.0, 120001)
    s = 1.0 / (1.0 + np.exp(-(z[None, :] + grid[:, None])))
    value = (y * np.log(s) + (1 - y) * np.log(1 - s)).sum(axis=1) - grid**2 / (2 * scale**2)
    return float(grid[np.argmax(value)])


@pytest.mark.parametrize(
    ("p", "y"),
    [
        ([0.2, 0.3, 0.25, 0.1], [1, 1, 1, 1]),
        ([0.9, 0.8, 0.7], [0, 0, 1]),
        ([0.5, 0.5, 0.5, 0.5], [1, 0, 1, 0]),
        ([0.05, 0.95, 0.6, 0.4, 0.2], [0, 1, 1, 0, 1]),
    ],
)
def test_the_intercept_is_the_map_refit_of_the_labels(p: list[float], y: list[int]) -> None:
    expected = _map_intercept(np.array(p), np.array(y, dtype=float), PRIOR_SCALE)
    found = intercept_shift(np.array(p), np.array(y, dtype=float), PRIOR_SCALE, 10.0)
    assert found == pytest.approx(expected, abs=2e-4)


def test_labels_that_agree_with_the_calibration_move_it_little() -> None:
    y = np.ones(12)
    confirmed = intercept_shift(np.full(12, 0.95), y, PRIOR_SCALE, MAX_SHIFT)
    surprising = intercept_shift(np.full(12, 0.2), y, PRIOR_SCALE, MAX_SHIFT)
    assert 0.0 < confirmed < 0.7 < 1.5 < surprising
    assert intercept_shift(np.full(12, 0.5), np.r_[np.ones(6), np.zeros(6)], 1.5, 3.0) == (
        pytest.approx(0.0, abs=1e-9)
    )
    assert intercept_shift(np.full(500, 0.01), np.ones(500), 1.5, MAX_SHIFT) == MAX_SHIFT
    assert intercept_shift(np.full(500, 0.99), np.zeros(500), 1.5, MAX_SHIFT) == -MAX_SHIFT


def test_a_probability_moves_in_log_odds_and_is_exact_without_a_move() -> None:
    p = np.array([0.2, 0.9, 0.4])
    moved = prior_probability(p, np.array([np.log(13.0), -1.0, 0.0]))
    logit = np.log(0.2 / 0.8)
    assert moved[0] == pytest.approx(1.0 / (1.0 + np.exp(-(logit + np.log(13.0)))))
    assert moved[0] > APPLY_THRESHOLD > p[0]
    assert moved[1] < p[1]
    assert moved[2] == p[2]


def test_adjust_reads_the_rig_and_joint_and_waits_for_the_minimum() -> None:
    prior = ReviewerPrior.from_decisions(
        "s", [("cmu", "RightLeg", 0.2, "accept")] * 4 + [("cmu", "LeftLeg", 0.2, "accept")] * 2
        + [("bandai", "RightLeg", 0.4, "reject")] * 9 + [("cmu", "RightLeg", 0.2, "maybe")],
    )  # fmt: skip
    assert MIN_DECISIONS == 3
    p = np.full(4, 0.3)
    moved, accepted, rejected = prior.adjust(
        p, "cmu", ["RightLeg", "LeftLeg", "RightArm", "RightLeg"]
    )
    assert accepted.tolist() == [4, 0, 0, 4]
    assert rejected.tolist() == [0, 0, 0, 0]
    assert moved[0] == moved[3] > 0.3
    assert moved[1] == moved[2] == 0.3  # two decisions (under the minimum), none
    moved, accepted, rejected = prior.adjust(p[:1], "bandai", ["RightLeg"])
    assert (accepted.tolist(), rejected.tolist()) == ([0], [9])
    assert moved[0] < 0.3
    assert (prior.n_accepted, prior.n_rejected) == (6, 9)  # "maybe" is no label


def test_only_decisions_on_intervals_scored_alike_move_a_probability() -> None:
    """Twelve rejected intervals the calibration scored 0.95 say nothing of one scored 0.2
    (their weights sum under the minimum); three scored 0.2 do."""
    far = ReviewerPrior.from_decisions("s", [("cmu", "RightLeg", 0.95, "reject")] * 12)
    near = ReviewerPrior.from_decisions("s", [("cmu", "RightLeg", 0.2, "reject")] * 3)
    p = np.array([0.2])
    assert far.adjust(p, "cmu", ["RightLeg"])[0][0] == 0.2
    assert far.adjust(np.array([0.9]), "cmu", ["RightLeg"])[0][0] < 0.9
    assert near.adjust(p, "cmu", ["RightLeg"])[0][0] < 0.2


def test_a_joint_whose_strong_intervals_were_right_does_not_raise_its_weak_ones() -> None:
    """Accepted intervals the calibration already scored high, and rejected weak ones: the
    refit leaves a weak new interval weak (a count of decisions would raise it)."""
    decisions = [("cmu", "RightLeg", 0.97, "accept")] * 10 + [
        ("cmu", "RightLeg", 0.3, "reject")
    ] * 4
    prior = ReviewerPrior.from_decisions("s", decisions)
    moved, accepted, rejected = prior.adjust(np.array([0.4]), "cmu", ["RightLeg"])
    assert (accepted.tolist(), rejected.tolist()) == ([0], [4])  # the ones that weigh
    assert moved[0] < 0.4 < APPLY_THRESHOLD


def test_the_prior_round_trips_through_json_and_its_hash_names_its_content() -> None:
    prior = _prior(12, 1)
    data = json.loads(json.dumps(prior.to_json()))
    again = ReviewerPrior.from_json(data)
    assert again == prior
    assert again.content_hash == prior.content_hash
    assert again.runs == ("run-a", "run-b")
    assert _prior(12, 2).content_hash != prior.content_hash
    assert _prior(12, 1, probability=0.3).content_hash != prior.content_hash
    summary = prior.summary()
    assert summary["hash"] == prior.content_hash
    assert (summary["accepted"], summary["rejected"], summary["joints"]) == (12, 1, 1)
    with pytest.raises(InputError, match="reviewer prior"):
        ReviewerPrior.from_json({"shoot": "s"})


def test_the_readout_says_who_moved_the_probability() -> None:
    evidence: dict[str, float | str] = {
        "calibrated": 0.14, "reviewer_probability": 0.68, "reviewer_accepted": 12.0,
        "reviewer_rejected": 0.0, "rule": "calibrated", "default": "applied",
    }  # fmt: skip
    text = decision_readout(evidence)
    assert "raised to 0.68 by 12 accepted intervals on this joint in this shoot" in text
    assert "which changed the default" in text
    lowered = {**evidence, "calibrated": 0.9, "reviewer_probability": 0.6,
               "reviewer_accepted": 1.0, "reviewer_rejected": 5.0}  # fmt: skip
    text = decision_readout(lowered)
    assert (
        "lowered to 0.60 by 5 rejected intervals on this joint in this shoot (1 accepted)" in text
    )
    assert "changed the default" not in text
    anatomy = {**evidence, "rule": "anatomy", "anatomy_deg": 31.0}
    assert decision_readout(anatomy).endswith(
        "; probability raised to 0.68 by 12 accepted intervals on this joint in this shoot"
    )


def test_accepted_decisions_apply_real_flips_the_calibration_leaves(corpus_dir: Path) -> None:
    motion = read_bvh(corpus_dir / "bvh" / "cmu" / "iclone" / "005_05.bvh")
    default = analyze_twist(motion)
    family = rig_family(motion.skeleton)
    by_calibration = [
        i for i in default.intervals
        if dict(i.evidence).get("rule") == "calibrated" and not i.applied
    ]  # fmt: skip
    assert by_calibration, "005_05 has intervals the calibration alone leaves"
    joint, scored = by_calibration[0].joint, by_calibration[0].confidence
    # Twenty decisions on intervals of that joint scored as the one the calibration leaves.
    accepted = analyze_twist(motion, prior=_prior(20, 0, joint, family, scored))
    rejected = analyze_twist(motion, prior=_prior(0, 20, joint, family, scored))
    other_rig = analyze_twist(motion, prior=_prior(20, 0, joint, "bandai", scored))
    for before, up, down, other in zip(
        default.intervals, accepted.intervals, rejected.intervals, other_rig.intervals, strict=True
    ):
        assert other == before  # labels of another rig family change nothing
        rule = dict(before.evidence).get("rule")
        if before.joint != joint or rule != "calibrated":
            # The hard rules and other joints are untouched (their probability may be recorded).
            assert (up.applied, down.applied) == (before.applied, before.applied)
            continue
        if "reviewer_accepted" not in dict(up.evidence):
            # Scored far from the decided intervals: they weigh too little to move it.
            assert abs(before.confidence - scored) > 0.1
            assert (up.applied, down.applied) == (before.applied, before.applied)
            continue
        assert dict(up.evidence)["reviewer_accepted"] == 20.0
        assert dict(up.evidence)["reviewer_probability"] > before.confidence
        assert dict(down.evidence)["reviewer_probability"] < before.confidence
        assert up.applied >= before.applied >= down.applied
        assert up.confidence == before.confidence  # the calibrated probability is kept
    first = next(u for u in accepted.intervals if u.id == by_calibration[0].id)
    flipped = [
        u for u, b in zip(accepted.intervals, default.intervals, strict=True)
        if u.applied and not b.applied
    ]  # fmt: skip
    assert flipped, "20 accepted decisions on the joint apply some interval the default left"
    assert "accepted intervals on this joint in this shoot" in decision_readout(
        dict(first.evidence)
    )


def test_a_probability_the_prior_cannot_move_says_so() -> None:
    evidence: dict[str, float | str] = {
        "calibrated": 0.0, "reviewer_probability": 0.00003, "reviewer_accepted": 12.0,
        "reviewer_rejected": 0.0, "rule": "min_evidence", "default": "listed",
    }  # fmt: skip
    assert decision_readout(evidence).endswith(
        "; probability not moved by 12 accepted intervals on this joint in this shoot"
    )
