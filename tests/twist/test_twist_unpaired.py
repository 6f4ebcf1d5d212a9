"""A natural roll step followed by a burst that does not cancel: injection and the mirror check."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.errors import InputError
from mocapqa.kinematics.quaternion import conjugate, multiply
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.angles import chain_geometry, wrap_angle
from mocapqa.twist.confidence import default_calibration
from mocapqa.twist.detect import RobustParams, detect_robust
from mocapqa.twist.inject_unpaired import UnpairedShape, inject_unpaired_bursts
from mocapqa.twist.intervals import FEATURES
from mocapqa_bench.natural import natural_error_figures
from mocapqa_bench.twist import IntervalRecord, find_bench_files
from mocapqa_bench.unpaired import run_unpaired_bench

FPS = 60.0


def _increments(
    parent_steps: dict[int, float], child_steps: dict[int, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Quiet rolls (seeded 0.1° noise) with the given steps in degrees, shape (300, 1)."""
    rng = np.random.default_rng(5)
    dp = rng.normal(0.0, 0.1, 300)
    dc = rng.normal(0.0, 0.1, 300)
    for frame, step in parent_steps.items():
        dp[frame] += step
    for frame, step in child_steps.items():
        dc[frame] += step
    return np.deg2rad(dp)[:, None], np.deg2rad(dc)[:, None]


# The right knee of 005_05 around frames 272–304, rounded: a counter-rotated step of 12–14° whose
# child counter-rotation is undone on the next frame, and 30 frames later a burst whose jumps
# add up to about −15°.
STEP = ({100: 12.4, 101: -3.5}, {100: -13.9, 101: 11.0})
BURST = ({130: 31.1, 131: -49.4, 132: 2.9}, {130: -35.3, 131: 46.0, 132: -4.1})


def test_a_burst_is_not_paired_with_a_step_the_child_does_not_keep() -> None:
    dp, dc = _increments({**STEP[0], **BURST[0]}, {**STEP[1], **BURST[1]})
    detection = detect_robust(dp, dc, FPS, RobustParams())
    events = np.flatnonzero(detection.candidates[:, 0])
    assert {100, 130, 131} <= set(events.tolist())
    # The clean stretch between the step and the burst keeps its roll.
    assert not np.any(detection.offsets[101:129, 0])
    # Without the check the two pair up and the stretch is moved by the step (about 12°).
    unchecked = detect_robust(dp, dc, FPS, replace(RobustParams(), mirror=0.0))
    assert np.rad2deg(np.abs(unchecked.offsets[101:129, 0])).min() > 10.0


def test_a_held_shift_released_by_a_burst_is_still_removed() -> None:
    # The same step, but the child keeps its counter-rotation: a twist error held for 30 frames
    # and released inside a burst.
    child_step = {100: -13.9, 101: 1.5}
    dp, dc = _increments({**STEP[0], **BURST[0]}, {**child_step, **BURST[1]})
    dc[131] += np.deg2rad(-12.0)
    detection = detect_robust(dp, dc, FPS, RobustParams())
    level = np.rad2deg(detection.offsets[101:129, 0])
    # Between the parent's own reading (8.9°) and the child's (12.4°).
    assert np.all((level > 8.0) & (level < 14.0))


def _parent_roll_change(
    motion: Motion, clean: np.ndarray, joint: int, axis: np.ndarray
) -> np.ndarray:
    """The twist about ``axis`` of ``q_before⁻¹ ⊗ q_after`` of one joint per frame, degrees."""
    relative = multiply(conjugate(motion.quats[:, joint]), clean[:, joint])
    angle = 2.0 * np.arctan2(relative[:, :3] @ axis, relative[:, 3])
    return np.rad2deg(wrap_angle(angle))


@pytest.mark.parametrize("rig", ["cmu", "iclone", "bandai"])
def test_the_unpaired_injection_has_the_shape_it_documents(
    takes: dict[str, Motion], rig: str
) -> None:
    motion = takes[rig]
    shape = UnpairedShape()
    corrupted, truth = inject_unpaired_bursts(motion, np.random.default_rng(3))
    targets, children = set(truth.targets), set(truth.children)
    # Only the targets and their children differ from the take: the natural parts.
    changed = np.any(truth.clean_quats != motion.quats, axis=-1)
    assert set(np.flatnonzero(changed.any(axis=0)).tolist()) <= targets | children
    # The error is the burst alone: 1–3 consecutive frames of alternating flips of 25–90°.
    error = np.any(corrupted.quats != truth.clean_quats, axis=-1)
    assert np.array_equal(error[:, list(targets)], truth.error_mask[:, list(targets)])
    for target in truth.targets:
        holds = [i for i in truth.intervals if i.joint == motion.skeleton.names[target]]
        frames = [i.start_frame for i in holds]
        assert 1 <= len(holds) <= shape.max_burst_frames
        assert frames == list(range(frames[0], frames[0] + len(holds)))
        values = np.array([i.offset_deg for i in holds])
        assert np.all((np.abs(values) >= 25.0) & (np.abs(values) <= 90.0))
        assert np.all(np.sign(values[1:]) == -np.sign(values[:-1]))
        # The natural step: held at 8–15° over the last frames before the burst, near but not
        # at the level before it afterwards.
        k = truth.targets.index(target)
        geometry = next(
            chain_geometry(motion.skeleton, c)
            for c in limb_chains(find_roles(motion.skeleton))
            if c.parent == target and c.child == truth.children[k]
        )
        roll = _parent_roll_change(motion, truth.clean_quats, target, geometry.axis)
        gap = round(shape.gap_s[0] * motion.fps) - 2
        held = roll[frames[0] - gap : frames[0]]
        assert 8.0 <= abs(held[-1]) <= 15.0
        np.testing.assert_allclose(held, held[-1], atol=1e-6)
        after = roll[frames[-1] + 1]
        assert 0.1 * abs(held[-1]) - 1e-6 <= abs(after) <= 0.4 * abs(held[-1]) + 1e-6


@pytest.mark.parametrize("seed", [3, 7])
def test_no_clean_frame_moves_on_a_jittery_step_before_a_burst(
    takes: dict[str, Motion], seed: int
) -> None:
    # Seeds whose step and burst the bracket matching paired before the mirror check (far
    # moves of 8.6° and 16.7°); seeds 1 of this take and 4 of the Character Creator take still
    # move far frames (docs/twist.md).
    corrupted, _ = inject_unpaired_bursts(takes["bandai"], np.random.default_rng(seed))
    figures = natural_error_figures(corrupted, analyze_twist(corrupted))
    assert figures.n_far_moved == 0
    unchecked = analyze_twist(corrupted, params=replace(RobustParams(), mirror=0.0))
    assert natural_error_figures(corrupted, unchecked).n_far_moved > 0


def test_the_shape_is_checked(takes: dict[str, Motion]) -> None:
    for bad in (
        {"step_deg": (15.0, 8.0)},
        {"gap_s": (0.1, 0.6)},
        {"max_burst_frames": 0},
        {"jitter_deg": (-1.0, 2.0)},
    ):
        with pytest.raises(InputError, match="Expected"):
            UnpairedShape(**bad)  # type: ignore[arg-type]
    motion = takes["bandai"]
    short = replace(motion, quats=motion.quats[:20], translations=motion.translations[:20],
                    euler_hint_deg=None)  # fmt: skip
    with pytest.raises(InputError, match="at least"):
        inject_unpaired_bursts(short, np.random.default_rng(0))


def _burst_features(child_burst: dict[int, float]) -> tuple[float, ...]:
    """The features of the one interval of a two-flip burst at frames 130–131 (quiet rolls)."""
    dp, dc = _increments({130: 30.0, 131: -38.0}, child_burst)
    (interval,) = detect_robust(dp, dc, FPS, RobustParams()).intervals
    assert interval.start_frame == 130
    return interval.features


def test_unreturned_is_the_net_the_child_counter_rotates() -> None:
    # The parent's net of −8° is natural when the child does not counter-rotate it (the burst
    # returned), a twist offset left over when the child counter-rotates it too.
    index = FEATURES.index("unreturned")
    returned = _burst_features({130: -30.0, 131: 30.0})
    kept = _burst_features({130: -30.0, 131: 38.0})
    assert returned[index] < 0.02
    assert kept[index] == pytest.approx(8.0 / 38.0, abs=0.02)
    # Both read the same net from their jumps; only the new feature tells them apart.
    closure = FEATURES.index("closure")
    assert abs(returned[closure] - kept[closure]) < 0.15
    # The shipped calibration rates the burst that left an offset lower, all else equal.
    calibration = default_calibration()
    probability = calibration.probability(np.array([returned, [*returned[:index], kept[index]]]))
    assert probability[0] > probability[1]


def test_a_burst_the_mirror_check_splits_off_is_flagged() -> None:
    dp, dc = _increments({**STEP[0], **BURST[0]}, {**STEP[1], **BURST[1]})
    split = FEATURES.index("split")
    checked = detect_robust(dp, dc, FPS, RobustParams()).intervals
    assert [i.features[split] for i in checked if i.start_frame >= 130] == [1.0]
    assert all(i.features[split] == 0.0 for i in checked if i.start_frame < 130)
    unchecked = detect_robust(dp, dc, FPS, replace(RobustParams(), mirror=0.0)).intervals
    assert unchecked
    assert all(i.features[split] == 0.0 for i in unchecked)


def test_the_unpaired_bench_labels_its_intervals(corpus_dir: Path) -> None:
    files = [f for f in find_bench_files(corpus_dir / "bvh") if f.rig == "iclone"][:1]
    records: list[IntervalRecord] = []
    figures = run_unpaired_bench(files, repeats=2, records=records)
    assert records
    assert {r.take for r in records} == {files[0].path.name}
    assert any(r.right for r in records)
    # The records are those of the refined takes the figures describe.
    assert sum(v.n_injected for v in figures.values()) == 2
