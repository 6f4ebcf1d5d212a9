"""Small offsets that natural roll steps of the rig reach are listed, not applied by default."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.angles import chain_geometry
from mocapqa.twist.confidence import decide
from mocapqa.twist.intervals import FEATURES
from mocapqa.twist.natural_roll import NaturalRoll, default_natural_roll, fit_natural_roll
from mocapqa.twist.refine import refine_quats


def _shifted(motion: Motion, segment: str, side: str, rows: slice, offset_deg: float) -> Motion:
    """The take with a level shift on ``rows`` of one chain, the child compensated."""
    chain = next(c for c in limb_chains(find_roles(motion.skeleton))
                 if c.segment == segment and c.side == side)  # fmt: skip
    offsets = np.zeros((motion.n_frames, 1))
    offsets[rows] = np.deg2rad(offset_deg)
    geometry = chain_geometry(motion.skeleton, chain)
    return replace(motion, quats=refine_quats(motion.quats, (geometry,), -offsets))


def test_a_6_degree_shift_under_the_rigs_natural_roll_is_listed_not_applied(
    takes: dict[str, Motion],
) -> None:
    natural = default_natural_roll()
    assert natural.level_deg("bandai", "upper_arm") > 6.0
    shifted = _shifted(takes["bandai"], "upper_arm", "left", slice(100, 115), 6.0)
    without = analyze_twist(shifted, natural_roll=NaturalRoll())
    assert [i.applied for i in without.intervals] == [True]  # the calibration alone applies it
    analysis = analyze_twist(shifted)
    (interval,) = analysis.to_json()["intervals"]
    assert (interval["start_frame"], interval["end_frame"]) == (100, 114)
    assert not interval["applied"]
    evidence = interval["evidence"]
    assert evidence["rule"] == "natural_roll"
    assert evidence["natural_roll_deg"] == round(natural.level_deg("bandai", "upper_arm"), 4)
    assert "natural upper arm roll (p99 16.5°)" in evidence["reason"]
    assert np.array_equal(analysis.refined.quats, shifted.quats)
    # Listed, and applied when asked for.
    assert analyze_twist(shifted, apply="all").intervals[0].applied


def test_a_rig_with_no_natural_roll_event_keeps_the_global_minimum(
    takes: dict[str, Motion],
) -> None:
    natural = default_natural_roll()
    for family in ("cmu", "character_creator"):
        for segment in ("clavicle", "upper_arm", "forearm", "upper_leg", "lower_leg"):
            assert natural.level_deg(family, segment) == 0.0
    shifted = _shifted(takes["iclone"], "upper_arm", "left", slice(200, 215), 6.0)
    (interval,) = analyze_twist(shifted).intervals
    assert interval.applied
    assert "natural_roll_deg" not in dict(interval.evidence)


def test_the_natural_roll_rule_blocks_every_other_rule_under_the_level() -> None:
    features = [0.0] * len(FEATURES)
    features[FEATURES.index("log_level_deg")] = float(np.log(8.0))
    small = list(features)
    large = list(features)
    large[FEATURES.index("log_level_deg")] = float(np.log(20.0))
    applied, rules = decide(np.array([0.99, 0.99, 0.99]), [small, large, small], None,
                            natural_deg=[16.5, 16.5, 0.0])  # fmt: skip
    assert applied.tolist() == [False, True, True]
    assert rules == ("natural_roll", "calibrated", "calibrated")


def test_the_levels_are_the_99th_percentile_of_the_clean_event_jumps(tmp_path: Path) -> None:
    jumps = {"bandai/upper_arm": np.arange(1.0, 101.0), "bandai/knee": np.zeros(0)}
    natural = fit_natural_roll(jumps, "test", tmp_path / "natural.json")
    assert natural.levels_deg == {
        "bandai/upper_arm": float(np.percentile(np.arange(1.0, 101.0), 99))
    }
    assert natural.events == {"bandai/upper_arm": 100}
    stored = NaturalRoll.from_json(json.loads((tmp_path / "natural.json").read_text()))
    assert stored.level_deg("bandai", "upper_arm") == round(
        natural.levels_deg["bandai/upper_arm"], 3
    )
    assert stored.level_deg("bandai", "lower_leg") == 0.0
