"""The fill's cross-validation: trials placed by motion, the blend of methods, the PCA trials
that refit without missing model markers, and the fill benchmark's real-take figures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tests.markers.conftest import load_take

from mocapqa.errors import OptionError
from mocapqa.markers.fill import FillContext, FillParams, fill_gaps, plan_gap
from mocapqa.markers.fill_cv import (
    blend_trial_error,
    blend_weights,
    marker_speed_sums,
    trial_starts,
    window_motion,
)
from mocapqa_bench.marker_fill import FillEvent, summarise, tune_leave_one_out
from mocapqa_bench.marker_fill_real import twin_figures

CMU = "c3d/cmu/cmu_02_05.c3d"
MARKER = 12


def test_window_motion_is_the_mean_speed_over_seen_steps() -> None:
    frames = np.arange(10, dtype=np.float64)
    positions = np.zeros((10, 2, 3))
    positions[:, 0, 0] = frames * 2.0  # 2 units a frame
    positions[:, 1, 1] = frames**2  # speeds 1, 3, 5, ...
    visible = np.ones((10, 2), dtype=bool)
    visible[4, 1] = False
    positions[4, 1] = np.nan
    sums = marker_speed_sums(positions, visible)
    starts = np.array([0, 5])
    np.testing.assert_allclose(window_motion(sums, np.array([0]), starts, 4), [2.0, 2.0])
    # Marker 1 over frames 5..8: steps 5→6, 6→7, 7→8 (11, 13, 15); over 2..5 only 2→3 is seen
    # (3→4 and 4→5 touch the missing frame).
    np.testing.assert_allclose(window_motion(sums, np.array([1]), starts, 4), [3.0, 13.0])
    np.testing.assert_allclose(window_motion(sums, np.array([1]), np.array([2]), 4), [5.0])


def test_trials_go_where_the_take_moves_as_over_the_gap() -> None:
    n, length = 400, 10
    ok = np.ones(n, dtype=bool)
    motion = np.full(n, 1.0)
    fast = np.r_[40:60, 300:340]
    motion[fast] = 8.0
    got = trial_starts(ok, length, 2, 2, 4, 200, local=False, motion=(motion, 8.0))
    assert got.size == 4
    assert np.isin(got, fast).all()
    spread = trial_starts(ok, length, 2, 2, 4, 200, local=False)
    assert not np.isin(spread, fast).all()
    both = trial_starts(ok, length, 2, 2, 4, 200, local=True, motion=(motion, 8.0))
    near = both[np.abs(both - 200) < 3 * length]
    assert near.size == 2
    assert np.isin(np.setdiff1d(both, near), fast).all()
    # Trials hardly overlap: at most one per block of the gap's length.
    assert np.unique(both // length).size == both.size


def test_blend_weights_lean_on_the_smaller_error() -> None:
    w = blend_weights(np.array([1.0, 2.0, 4.0]), 2.0)
    np.testing.assert_allclose(w.sum(), 1.0)
    np.testing.assert_allclose(w, np.array([16.0, 4.0, 1.0]) / 21.0)
    np.testing.assert_allclose(blend_weights(np.array([0.0, 3.0]), 2.0), [1.0, 0.0])


def test_blend_trial_error_weighs_each_trial_from_the_others() -> None:
    truth = np.zeros((3, 2, 3))
    fills = np.zeros((3, 2, 2, 3))
    fills[:, 0, :, 0] = [[1.0], [1.0], [3.0]]  # method 0 off by 1, 1, 3
    fills[:, 1, :, 0] = [[-2.0], [-2.0], [-2.0]]  # method 1 off by 2 everywhere
    squared = np.sum((fills - truth[:, None]) ** 2, axis=(2, 3))
    got = blend_trial_error(squared, fills, truth, 2.0)
    expected = []
    for t in range(3):
        rest = [s for s in range(3) if s != t]
        rmse = np.sqrt(squared[rest].sum(axis=0) / (2 * len(rest)))
        w = rmse**-2 / np.sum(rmse**-2)
        expected.append(w[0] * fills[t, 0, 0, 0] + w[1] * fills[t, 1, 0, 0])
    np.testing.assert_allclose(got, np.sqrt(np.mean(np.square(expected))))
    # Weights from the same trial would have put more on method 0 at trial 2 where it is worse.
    assert got != pytest.approx(blend_trial_error(squared[:1], fills[:1], truth[:1], 2.0))


@pytest.fixture(scope="module")
def cmu(corpus_dir: Path) -> tuple[np.ndarray, float]:
    take = load_take(corpus_dir / CMU)
    return take.positions, take.fps


def test_the_blend_is_the_weighted_fill_of_the_methods(cmu: tuple[np.ndarray, float]) -> None:
    positions, fps = cmu
    a, b = 700, 700 + round(0.4 * fps) - 1
    hidden = positions.copy()
    hidden[a : b + 1, MARKER] = np.nan
    plan = plan_gap(FillContext(hidden, fps, FillParams(), 1.0), MARKER, a, b)
    names = [x for x in ("spline", "rigid", "pca", "relative") if x in plan.fills]
    assert len(names) >= 2
    assert "blend" in plan.fills
    w = blend_weights(np.array([plan.errors[x] for x in names]), FillParams().blend_power)
    np.testing.assert_allclose(
        plan.fills["blend"], sum(wi * plan.fills[x] for wi, x in zip(w, names, strict=True))
    )
    assert np.isfinite(plan.errors["blend"])
    off = plan_gap(FillContext(hidden, fps, FillParams(blend_power=0.0), 1.0), MARKER, a, b)
    assert "blend" not in off.fills
    assert "blend" not in off.errors


def test_pca_is_cross_validated_when_no_stretch_shows_every_model_marker(
    cmu: tuple[np.ndarray, float],
) -> None:
    """Model markers blink in turn so that no stretch of the gap's length shows all of them:
    the PCA trials refit without the missing ones instead of leaving the method untried."""
    positions, fps = cmu
    a, b = 1200, 1200 + round(0.8 * fps) - 1
    hidden = positions.copy()
    hidden[a : b + 1, MARKER] = np.nan
    take = FillContext(hidden, fps, FillParams(), 1.0)
    model = plan_gap(take, MARKER, a, b).model
    length = b - a + 1
    blink = hidden.copy()
    for k, j in enumerate(model[:6].tolist()):
        for s in range(k * length // 6, blink.shape[0], length // 2):
            if not a - 3 <= s <= b + 3:
                blink[s, j] = np.nan
    plan = plan_gap(FillContext(blink, fps, FillParams(), 1.0), MARKER, a, b)
    assert "pca" in plan.fills
    assert np.isfinite(plan.errors["pca"])


def test_new_settings_are_checked() -> None:
    with pytest.raises(OptionError):
        FillParams(cv_match="nearest")
    with pytest.raises(OptionError):
        FillParams(blend_power=-1.0)
    with pytest.raises(OptionError):
        FillParams(cv_motion_markers=0)


def test_fill_marks_blended_gaps_like_any_other(cmu: tuple[np.ndarray, float]) -> None:
    positions, fps = cmu
    hidden = positions[:900].copy()
    hidden[300:330, MARKER] = np.nan
    hidden[500:560, MARKER + 1] = np.nan
    result = fill_gaps(hidden, fps, apply="all")
    for g in result.gaps:
        assert g.method is None or g.method in g.errors
        assert result.filled[g.start : g.end + 1, g.marker].all() == g.applied


def test_summarise_counts_the_blend() -> None:
    sq = {"spline": 4.0, "rigid": 1.0, "pca": 1.0, "relative": 1.0, "auto": 1.0}
    events = [FillEvent("x", 0, 4, False, sq, "blend"), FillEvent("x", 0, 4, True, sq, "pca")]
    (row, *_) = summarise(events)
    assert row["chosen"]["blend"] == 1
    assert row["chosen"]["pca"] == 1


def test_real_gapped_take_figures(corpus_dir: Path) -> None:
    every = twin_figures(corpus_dir, "all")
    assert every["gaps"] == every["filled_gaps"] == 10
    assert every["filled_samples"] == 145
    assert np.isfinite(every["expected_mm"])
    assert every["expected_mm"] > 0
    assert every["rmse_mm"] < 25.0
    confident = twin_figures(corpus_dir, "confident")
    assert 0 < confident["filled_gaps"] < 10
    assert confident["rmse_mm"] < every["rmse_mm"]


def test_leave_one_out_scores_each_file_with_what_the_others_chose(corpus_dir: Path) -> None:
    files = ("c3d/btk/Eb015pr.c3d", "c3d/cmu/cmu_02_05.c3d")
    candidates = (FillParams(blend_power=0.0), FillParams(blend_power=2.0))
    choices, held = tune_leave_one_out(corpus_dir, candidates, (0,), files, events_per_bin=1)
    # Each candidate alone: its events on every file.
    alone = [
        tune_leave_one_out(corpus_dir, [c], (0,), files, events_per_bin=1)[1] for c in candidates
    ]
    assert [c["file"] for c in choices] == list(files)
    for choice in choices:
        other = [
            [e for e in events if e.file != choice["file"] and np.isfinite(e.sq_error["auto"])]
            for events in alone
        ]
        scores = [
            np.sqrt(sum(e.sq_error["auto"] for e in ev) / sum(e.frames for e in ev)) for ev in other
        ]
        np.testing.assert_allclose(choice["train_auto_mm"], scores)
        assert choice["chosen"] == int(np.argmin(scores))
        mine = [e for e in held if e.file == choice["file"]]
        # repr: the events' NaN errors (methods that did not fill) compare unequal.
        assert repr(mine) == repr([e for e in alone[choice["chosen"]] if e.file == choice["file"]])
