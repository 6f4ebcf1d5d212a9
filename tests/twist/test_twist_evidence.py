"""Decay tails of bursts, the local-speed rule, the minimum-evidence rule and the isotonic map."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mocapqa.errors import InputError
from mocapqa.twist.choice import choose_intervals
from mocapqa.twist.confidence import (
    APPLY_THRESHOLD,
    MAX_DISAGREEMENT,
    MIN_LEVEL_DEG,
    Calibration,
    default_calibration,
    fit_calibration,
    has_evidence,
)
from mocapqa.twist.detect import DetectedInterval, RobustParams, detect_robust
from mocapqa.twist.intervals import FEATURES, ChainSettings, chain_intervals

FPS = 60.0


def _burst_with_tail() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A roll at 0.5°/frame with 0.2° noise, with a flip of 60° at frames 100–101 that returns
    to 6° and then decays by 1.5° per frame over frames 103–106, below the event threshold (the
    offset per frame, the parent's increments and the child's counter-increments, radians)."""
    n = 200
    rng = np.random.default_rng(3)
    offset = np.zeros(n)
    offset[100:102] = 60.0
    offset[102:106] = [6.0, 4.5, 3.0, 1.5]
    step = np.diff(offset, prepend=0.0)
    parent = np.deg2rad(0.5 + rng.normal(0.0, 0.2, n) + step)
    child = np.deg2rad(-0.2 + rng.normal(0.0, 0.2, n) - step)
    return np.deg2rad(offset), parent, child


def test_a_decay_tail_after_a_burst_gets_the_level_still_to_go() -> None:
    truth, parent, child = _burst_with_tail()
    with_tail = detect_robust(parent[:, None], child[:, None], FPS, RobustParams())
    without = detect_robust(parent[:, None], child[:, None], FPS, RobustParams(tail_s=0.0))
    assert np.flatnonzero(with_tail.candidates[:, 0]).tolist() == [100, 102]
    found = np.rad2deg(with_tail.offsets[:, 0])
    assert np.allclose(found, np.rad2deg(truth), atol=1.0)
    # Without tails the tail frames are left as they are, and the flip's level is off by
    # half the tail's start (the ends do not quite cancel).
    assert np.allclose(np.rad2deg(without.offsets[100:102, 0]), 57.0, atol=1.0)
    assert np.all(without.offsets[102:, 0] == 0.0)
    (interval,) = with_tail.intervals
    assert (interval.start_frame, interval.end_frame) == (100, 105)


def test_a_tail_never_reaches_past_its_length_or_into_the_next_interval() -> None:
    n = 40
    frames = np.array([10, 12, 14, 16])
    jumps = np.deg2rad([40.0, -37.0, 40.0, -37.0])
    small = np.zeros(n)
    small[13] = np.deg2rad(-3.0)  # the first flip's tail, cut by the event at frame 14
    small[17:30] = np.deg2rad(-0.5)  # steps in the release's direction for 13 frames
    increments = small.copy()
    increments[frames] = jumps
    settings = ChainSettings(np.deg2rad(2.0), np.deg2rad(0.1), FPS, 0.2, 0.5, 0.01, 2.0, 0.1)
    offsets, found = chain_intervals(
        frames, jumps, np.zeros(4), increments, np.zeros(n), settings, small
    )
    assert [(f.start_frame, f.end_frame) for f in found] == [(10, 12), (14, 21)]
    assert np.allclose(np.rad2deg(offsets[10:14]), [40.0, 40.0, 3.0, 0.0])
    # The second flip's tail: at most round(0.1 s × 60) = 6 frames.
    assert np.allclose(np.rad2deg(offsets[16:22]), [3.0, 2.5, 2.0, 1.5, 1.0, 0.5])
    assert np.all(offsets[22:] == 0.0)
    without, _ = chain_intervals(
        frames, jumps, np.zeros(4), increments, np.zeros(n), replace(settings, tail_s=0.0), small
    )
    assert np.all(without[12:14] == 0.0)
    assert np.all(without[16:] == 0.0)


def test_a_step_within_the_local_roll_speed_is_not_an_event() -> None:
    # The parent rolls at 6°/frame and slows to 1°/frame for one frame while the child
    # (rolling the other way) takes the 5° up: against the 2° floor an event, against the
    # local roll speed of 6°/frame none.
    parent = np.full(120, np.deg2rad(-6.0))
    child = np.full(120, np.deg2rad(4.8))
    parent[60] += np.deg2rad(5.0)
    child[60] -= np.deg2rad(5.0)
    off = RobustParams(speed_factor=0.0)
    assert detect_robust(parent[:, None], child[:, None], 30.0, off).candidates[60, 0]
    assert not detect_robust(parent[:, None], child[:, None], 30.0, RobustParams()).candidates.any()
    # A real flip on top of the fast roll is still found.
    flip = np.zeros(120)
    flip[30], flip[31] = np.deg2rad(40.0), np.deg2rad(-40.0)
    found = detect_robust((parent + flip)[:, None], (child - flip)[:, None], 30.0, RobustParams())
    assert found.candidates[30, 0]
    assert found.candidates[31, 0]


def _interval(level_deg: float, confidence: float) -> DetectedInterval:
    features = (5.0, 0.0, 0.0, 0.0, -2.0, float(np.log(level_deg)))
    return DetectedInterval(0, 10, 12, np.deg2rad(level_deg), confidence, features)


def test_an_interval_the_outside_roll_contradicts_is_not_applied_by_default() -> None:
    index = FEATURES.index("disagreement")
    agreeing = list(_interval(20.0, 0.99).features)
    contradicted = list(agreeing)
    agreeing[index] = 0.9 * MAX_DISAGREEMENT
    contradicted[index] = MAX_DISAGREEMENT
    assert has_evidence(agreeing)
    assert not has_evidence(contradicted)
    detected = np.zeros((20, 1))
    detected[10:13, 0] = np.deg2rad(20.0)

    class _Chain:
        parent, side, segment = 0, "left", "upper_arm"

    class _Geometry:
        chain = _Chain()

    for features, expected in ((agreeing, True), (contradicted, False)):
        interval = DetectedInterval(0, 10, 12, np.deg2rad(20.0), 0.99, tuple(features))
        _, (entry,) = choose_intervals(
            [interval], detected, [_Geometry()], ["UpperArm_L"], "confident", True
        )  # type: ignore[list-item]
        assert entry.applied is expected


def test_a_fast_natural_roll_of_a_clean_take_is_reported_not_applied(corpus_dir: Path) -> None:
    # The kick's right upper arm rolls 2–9° per frame at 30 fps around frames 186–200; the
    # counter-rotated steps there pair into a 5.3° interval that the roll outside the interval
    # contradicts (disagreement 1.8). The calibration with the ``unreturned`` feature rates it
    # under the apply threshold too (0.83 before); either would keep it from being applied.
    from mocapqa.io.bvh import read_bvh
    from mocapqa.twist.analysis import analyze_twist

    motion = read_bvh(corpus_dir / "bvh" / "bandai" / "dataset-1_kick_normal_001.bvh")
    analysis = analyze_twist(motion)
    found = [
        (i, f)
        for i, f in zip(analysis.intervals, analysis.found, strict=True)
        if i.joint == "UpperArm_R" and i.start_frame <= 194 and i.end_frame >= 193
    ]
    assert len(found) == 1
    interval, detected = found[0]
    assert interval.confidence < APPLY_THRESHOLD
    assert detected.features[FEATURES.index("disagreement")] >= MAX_DISAGREEMENT
    assert not interval.applied
    assert not any(i.applied for i in analysis.intervals)
    assert np.array_equal(analysis.refined.quats, motion.quats)


def test_small_intervals_are_reported_but_not_applied_by_default() -> None:
    small, large = _interval(0.8 * MIN_LEVEL_DEG, 0.99), _interval(2 * MIN_LEVEL_DEG, 0.99)
    assert not has_evidence(small.features)
    assert has_evidence(large.features)
    assert has_evidence(())
    detected = np.zeros((20, 1))
    detected[10:13, 0] = np.deg2rad(4.0)

    class _Chain:
        parent, side, segment = 0, "left", "upper_arm"

    class _Geometry:
        chain = _Chain()

    for interval, expected in ((small, False), (large, True)):
        _, (entry,) = choose_intervals(
            [interval], detected, [_Geometry()], ["UpperArm_L"], "confident", True
        )  # type: ignore[list-item]
        assert entry.applied is expected
        _, (forced,) = choose_intervals(
            [interval], detected, [_Geometry()], ["UpperArm_L"], "all", True
        )  # type: ignore[list-item]
        assert forced.applied


def test_the_isotonic_map_is_monotone_fitted_out_of_fold_and_round_trips(
    tmp_path: Path,
) -> None:
    rng = np.random.default_rng(1)
    features = rng.normal(size=(400, len(FEATURES)))
    # Right when the first feature is large, but only about 60 % of the time in the middle:
    # the logistic score is over-confident there and the isotonic map corrects it.
    right = (features[:, 0] > 1.0) | ((features[:, 0] > -0.5) & (rng.random(400) < 0.6))
    groups = [f"take{k % 20}" for k in range(400)]
    fitted = fit_calibration(features, right.tolist(), "test", tmp_path / "c.json", groups)
    assert len(fitted.isotonic_x) >= 2
    assert np.all(np.diff(fitted.isotonic_x) >= 0)
    assert np.all(np.diff(fitted.isotonic_y) >= 0)
    again = Calibration.from_json(json.loads((tmp_path / "c.json").read_text()))
    p = again.probability(features)
    assert np.allclose(p, fitted.probability(features))
    assert np.all((p >= 0) & (p <= 1))
    middle = (features[:, 0] > -0.5) & (features[:, 0] <= 1.0)
    assert abs(float(p[middle].mean()) - float(right[middle].mean())) < 0.15
    # A calibration without an isotonic map (an older file) is the logistic score itself.
    plain = {k: v for k, v in again.to_json().items() if not k.startswith("isotonic")}
    logistic = Calibration.from_json(plain)
    assert np.allclose(logistic.probability(features), again.score(features))
    with pytest.raises(InputError, match="isotonic"):
        Calibration.from_json({**plain, "isotonic_x": [0.1, 0.2], "isotonic_y": [0.5]})


def test_the_shipped_calibration_has_an_isotonic_map() -> None:
    shipped = default_calibration()
    assert len(shipped.isotonic_x) >= 2
    assert shipped.isotonic_y[0] <= shipped.isotonic_y[-1]


def test_a_jump_is_read_mostly_from_the_quieter_of_parent_and_child() -> None:
    # A jittery parent roll (1.5° per frame) next to a still child: a 12° shift held for 20
    # frames is read from the child's exact counter-step, so onset and release cancel.
    rng = np.random.default_rng(5)
    n = 200
    parent = np.deg2rad(rng.normal(0.0, 1.5, n))
    child = np.deg2rad(rng.normal(0.0, 0.05, n))
    shift = np.zeros(n)
    shift[100:120] = np.deg2rad(12.0)
    step = np.diff(shift, prepend=0.0)
    dp, dc = (parent + step)[:, None], (child - step)[:, None]
    params = RobustParams(min_threshold_deg=2.0, noise_factor=0.0, weighted_jumps=True)
    weighted = detect_robust(dp, dc, FPS, params)
    rows = weighted.candidates[:, 0]
    assert rows[100]
    assert rows[120]
    assert np.allclose(np.rad2deg(weighted.offsets[100:120, 0]), 12.0, atol=0.3)
    # The child's residuals are nearly exact; the parent's carry its jitter.
    plain = detect_robust(dp, dc, FPS, RobustParams(min_threshold_deg=2.0, noise_factor=0.0,
                                                    weighted_jumps=False))  # fmt: skip
    error_weighted = np.abs(np.rad2deg(weighted.offsets[100:120, 0]) - 12.0).max()
    error_plain = np.abs(np.rad2deg(plain.offsets[100:120, 0]) - 12.0).max(initial=12.0)
    assert error_weighted <= error_plain


def test_new_parameters_are_checked() -> None:
    with pytest.raises(InputError, match="speed_factor"):
        RobustParams(speed_factor=-1.0)
    with pytest.raises(InputError, match="tail_s"):
        RobustParams(tail_s=-0.1)


def test_the_noise_allowance_admits_a_shift_read_through_a_noisy_child() -> None:
    # A quiet parent and a child rolling with 4° of noise per frame: the child's counter-step
    # of a 10° shift is off by its noise, which the plain 0.5 × step allowance rejects at
    # one end or the other; one noise scale more admits both.
    rng = np.random.default_rng(11)
    n = 300
    parent = np.deg2rad(rng.normal(0.0, 0.05, n))
    child = np.deg2rad(rng.normal(0.0, 4.0, n))
    shift = np.zeros(n)
    shifts = [(40 + 40 * k, 60 + 40 * k) for k in range(6)]
    for start, end in shifts:
        shift[start:end] = np.deg2rad(10.0)
    step = np.diff(shift, prepend=0.0)
    dp, dc = (parent + step)[:, None], (child - step)[:, None]
    strict = detect_robust(dp, dc, FPS, RobustParams(noise_factor=0.0))
    loose = detect_robust(dp, dc, FPS, RobustParams(noise_factor=0.0, mismatch_noise=1.0))
    ends = [f for pair in shifts for f in pair]
    assert loose.candidates[ends, 0].sum() > strict.candidates[ends, 0].sum()


def test_ends_cancel_within_their_measurement_uncertainty() -> None:
    # A 9.8° level shift held over frames 40–59: the child counter-rotates exactly, the
    # parent's release is read 4.4° too large (natural jitter on that frame). The jumps
    # (means of the two readings) are −9.4° and +12.0°: their net 2.6° exceeds the closure
    # tolerance max(2°, 0.2 × 12°), but not that plus the root sum of squares of half the
    # gaps between the readings (0.4° and 2.2°).
    n = 120
    parent = np.zeros(n)
    child = np.zeros(n)
    parent[40], child[40] = np.deg2rad(-9.0), np.deg2rad(9.8)
    parent[60], child[60] = np.deg2rad(14.2), np.deg2rad(-9.8)
    strict = detect_robust(parent[:, None], child[:, None], FPS, RobustParams(closure_noise=0.0))
    assert strict.candidates[[40, 60], 0].all()
    assert strict.intervals == ()
    assert np.all(strict.offsets == 0.0)
    loose = detect_robust(parent[:, None], child[:, None], FPS, RobustParams())
    (interval,) = loose.intervals
    assert (interval.start_frame, interval.end_frame) == (40, 59)
    assert -11.0 < np.rad2deg(interval.offset_rad) < -9.0
    assert np.all(loose.offsets[:40] == 0.0)
    assert np.all(loose.offsets[60:] == 0.0)


def test_chain_intervals_take_each_jumps_uncertainty() -> None:
    n = 100
    frames = np.array([30, 50])
    jumps = np.deg2rad([-9.0, 11.6])  # net 2.6° against a tolerance of 2.32°
    increments = np.zeros(n)
    increments[frames] = jumps
    settings = ChainSettings(np.deg2rad(2.0), np.deg2rad(0.1), FPS, 0.2, 0.5, 0.1, 2.0)
    args = (frames, jumps, np.zeros(2), increments, np.zeros(n), settings, None)
    without, none = chain_intervals(*args)
    assert none == []
    assert np.all(without == 0.0)
    _, still_none = chain_intervals(*args, np.deg2rad([0.1, 0.1]))
    assert still_none == []
    # Two events within one burst (0.1 s) get no allowance: flips of a burst pair up wrongly
    # often enough without it.
    close = np.array([30, 34])
    steps = np.zeros(n)
    steps[close] = jumps
    burst = (close, jumps, np.zeros(2), steps, *args[4:])
    plain, _ = chain_intervals(*burst)
    allowed, _ = chain_intervals(*burst, np.deg2rad([0.05, 1.7]))
    assert np.any(plain != 0.0)
    assert np.array_equal(plain, allowed)
    offsets, (found,) = chain_intervals(*args, np.deg2rad([0.05, 1.7]))
    assert (found.start_frame, found.end_frame) == (30, 49)
    # The level accumulated from the jumps, their net spread evenly: −9.0 − 1.3.
    assert np.allclose(np.rad2deg(offsets[30:50]), -10.3, atol=1e-6)
    assert np.all(offsets[:30] == 0.0)
    assert np.all(offsets[50:] == 0.0)


def test_a_large_shift_closes_across_small_steps_that_look_like_a_burst() -> None:
    # A −123° shift held over frames 202–218 at 30 fps (the onset and release of a Bandai
    # upper arm), with natural counter-rotated steps of −5.8° and −3.3° at frames 209–210
    # (one frame apart: a burst by timing) and −4.2° at 214. The burst's flips are all within
    # the closure tolerance of the release (0.2 × 122°), so the release closes the onset.
    n = 300
    frames = np.array([202, 209, 210, 214, 219])
    jumps = np.deg2rad([-122.6, -5.8, -3.3, -4.2, 122.2])
    increments = np.zeros(n)
    increments[frames] = jumps
    settings = ChainSettings(np.deg2rad(2.0), np.deg2rad(0.5), 30.0, 0.2, 0.5, 0.1, 2.0)
    args = (frames, jumps, np.zeros(5), increments, np.zeros(n), settings)
    offsets, (found,) = chain_intervals(*args)
    assert (found.start_frame, found.end_frame) == (202, 218)
    assert np.all(np.rad2deg(offsets[202:219]) < -110.0)
    assert np.all(offsets[:202] == 0.0)
    assert np.all(offsets[219:] == 0.0)
    # A burst of real flips (40° and 20°, beyond that tolerance, not cancelling each other)
    # still cannot be closed from
    # outside: its last flip is never paired with an unrelated event far away.
    flips = np.deg2rad([-122.6, -40.0, 20.0, -4.2, 122.2])
    steps = np.zeros(n)
    steps[frames] = flips
    offsets, found_all = chain_intervals(frames, flips, *args[2:3], steps, *args[4:])
    assert not any((f.start_frame, f.end_frame) == (202, 218) for f in found_all)


def _held_shift(jitter_deg: float) -> np.ndarray:
    """Roll increments of a −10° shift held over frames 30–49 of 100, the roll inside
    alternating by ``jitter_deg`` (+ on even frames from 32 to 48), degrees."""
    roll = np.zeros(100)
    roll[30:50] = -10.0
    roll[32:49:2] += jitter_deg
    return np.deg2rad(np.diff(roll, prepend=0.0))


def test_the_outside_roll_overrules_the_jumps_only_beyond_its_own_scatter() -> None:
    frames = np.array([30, 50])
    jumps = np.deg2rad([-10.0, 10.0])

    def levels(increments: np.ndarray, precision: float) -> np.ndarray:
        settings = ChainSettings(
            np.deg2rad(2.0), np.deg2rad(0.1), FPS, 0.2, 0.5, 0.1, 2.0, precision=precision
        )
        offsets, _ = chain_intervals(
            frames, jumps, np.zeros(2), increments, np.zeros(100), settings
        )
        return np.rad2deg(offsets)

    # Inside, the roll swings by 26° from frame to frame: its mean (1.7°) contradicts the
    # jumps' −10°, but by less than twice its own scatter (17°), so the jumps' level stays.
    jittery = _held_shift(26.0)
    assert np.all(levels(jittery, 0.0) == 0.0)
    kept = levels(jittery, 2.0)
    assert np.allclose(kept[30:50], -10.0)
    assert np.all(kept[:30] == 0.0)
    assert np.all(kept[50:] == 0.0)
    # A calm roll that stays at its natural level while two events claim a shift: the
    # contradiction is far beyond the scatter, and no frame is moved.
    calm = np.zeros(100)
    assert np.all(levels(calm, 2.0) == 0.0)


def test_the_disagreement_limit_is_chosen_without_the_rig_it_is_checked_on() -> None:
    from mocapqa_bench.calibration import disagreement_loro
    from mocapqa_bench.twist import IntervalRecord

    def record(rig: str, disagreement: float, right: bool) -> IntervalRecord:
        features = (5.0, 0.1, 0.0, disagreement, -2.0, float(np.log(20.0)))
        return IntervalRecord(rig, False, f"{rig}.bvh", features, 0.9, right)

    records = [
        record("a", 1.1, True),  # a right interval at 1.1: without "b", 1.0 is ruled out
        record("a", 0.2, True),
        record("b", 1.3, True),  # without "a", 1.0 and 1.25 are ruled out
        record("b", 1.6, False),
        record("c", 0.1, True),
        record("c", 1.8, False),
        record("c", 1.2, True),
    ]
    checks = {c.rig: c for c in disagreement_loro(records)}
    assert checks["a"].chosen == 1.5  # chosen on b and c: 1.3 and 1.2 are right
    assert (checks["a"].right_blocked, checks["a"].wrong_blocked) == (0, 0)
    assert checks["b"].chosen == 1.25  # chosen on a and c: right up to 1.2
    assert (checks["b"].right_blocked, checks["b"].wrong_blocked) == (1, 1)
    assert checks["c"].chosen == 1.5
    assert (checks["c"].right_blocked, checks["c"].wrong_blocked) == (0, 1)
    assert (checks["c"].right_applied, checks["c"].wrong_applied) == (2, 1)


def test_an_onset_with_a_small_step_beside_it_is_still_closed_by_its_release() -> None:
    # The guide take's right arm: an 85° onset at frame 32, a 3° natural roll step at 33 (an
    # event too: counter-rotated, above the chain's 2° threshold) and the lone 82° release at
    # 47. The two events at 32–33 form a cluster, but not a burst of flips: the release closes
    # it as a whole and the level is held over 32–46.
    n = 80
    frames = np.array([32, 33, 47])
    jumps = np.deg2rad([-85.0, -3.0, 83.0])
    increments = np.zeros(n)
    increments[frames] = jumps
    settings = ChainSettings(np.deg2rad(2.0), np.deg2rad(0.5), 30.0, 0.2, 0.5, 0.1, 2.0)
    offsets, found = chain_intervals(frames, jumps, np.zeros(3), increments, np.zeros(n), settings)
    assert [(f.start_frame, f.end_frame) for f in found] == [(32, 46)]
    assert np.allclose(np.rad2deg(offsets[34:47]), -88.0, atol=3.5)
    # Two comparable flips stay one burst that a lone event far away may not end.
    flips = np.deg2rad([-85.0, 60.0, 25.0])
    _, bursts = chain_intervals(frames, flips, np.zeros(3), increments, np.zeros(n), settings)
    assert all(f.end_frame < 47 for f in bursts)
