"""Gap filling on real C3D takes: each method, the per-gap choice, what fill_gaps leaves alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tests.markers.conftest import load_take

from mocapqa.core.arrays import column_runs
from mocapqa.errors import OptionError, ShapeError
from mocapqa.markers.fill import FillContext, FillParams, fill_gaps, plan_gap
from mocapqa_bench.marker_fill import fill_table

CMU = "c3d/cmu/cmu_02_05.c3d"
TENNIS = "c3d/optitrack/kinematics_tennis_serve.c3d"
TENNIS_GAPS = "c3d/optitrack/kinematics_tennis_serve_nan.c3d"
GAIT = "c3d/btk/Eb015pr.c3d"

# CMU 02_05 marker 12 (a left-arm marker) is recorded over frames 600..800, as are its donors.
MARKER = 12


def load(path: Path) -> tuple[np.ndarray, float]:
    """Positions (F, M, 3) in the file's unit with NaN where missing, and rate."""
    take = load_take(path)
    return take.positions, take.fps


@pytest.fixture(scope="module")
def cmu(corpus_dir: Path) -> tuple[np.ndarray, float]:
    return load(corpus_dir / CMU)


@pytest.fixture(scope="module")
def gait(corpus_dir: Path) -> tuple[np.ndarray, float]:
    return load(corpus_dir / GAIT)


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))


def hide(positions: np.ndarray, m: int, a: int, b: int) -> np.ndarray:
    out = positions.copy()
    out[a : b + 1, m] = np.nan
    return out


def bits(x: np.ndarray) -> np.ndarray:
    return x.view(np.uint64)


def test_each_method_reproduces_a_hidden_real_stretch(cmu: tuple[np.ndarray, float]) -> None:
    positions, fps = cmu
    a, b = 700, 700 + round(0.25 * fps) - 1
    assert not np.isnan(positions[a - 40 : b + 40, MARKER]).any()
    plan = plan_gap(
        FillContext(hide(positions, MARKER, a, b), fps, FillParams(), 1.0), MARKER, a, b
    )
    truth = positions[a : b + 1, MARKER]
    assert set(plan.fills) == {"spline", "rigid", "pca", "relative", "blend"}
    assert plan.donors.size >= 3
    for name, limit in (("spline", 20.0), ("rigid", 15.0), ("pca", 20.0), ("relative", 20.0)):
        assert rmse(plan.fills[name], truth) < limit, name
        assert np.isfinite(plan.errors[name]), name


def test_auto_beats_spline_on_half_second_gap_with_donors(cmu: tuple[np.ndarray, float]) -> None:
    positions, fps = cmu
    a, b = 1200, 1200 + round(0.5 * fps) - 1
    hidden = hide(positions, MARKER, a, b)
    result = fill_gaps(hidden, fps, apply="all")
    (gap,) = [g for g in result.gaps if g.marker == MARKER and g.start == a]
    assert gap.method in ("rigid", "pca", "blend")
    assert gap.applied
    context = FillContext(hidden, fps, FillParams(), 1.0)
    plan = plan_gap(context, MARKER, a, b)
    truth = positions[a : b + 1, MARKER]
    auto = rmse(result.positions[a : b + 1, MARKER], truth)
    assert auto < 0.5 * rmse(plan.fills["spline"], truth)
    # The expected error is the cross-validated one, of the same order as the real one.
    assert gap.expected_error < 4 * auto + 5.0


def test_outside_fills_bit_identical_and_mask_exact(gait: tuple[np.ndarray, float]) -> None:
    positions, fps = gait
    before = positions.copy()
    result = fill_gaps(positions, fps, apply="all")
    assert bits(positions).tobytes() == bits(before).tobytes()
    applied = [g for g in result.gaps if g.applied]
    assert applied
    expected = np.zeros(positions.shape[:2], dtype=bool)
    for g in applied:
        expected[g.start : g.end + 1, g.marker] = True
    np.testing.assert_array_equal(result.filled, expected)
    assert np.isfinite(result.positions[result.filled]).all()
    assert np.isnan(positions[result.filled]).all()
    outside = ~result.filled
    np.testing.assert_array_equal(bits(result.positions)[outside], bits(positions)[outside])


def test_confident_applies_only_confident(gait: tuple[np.ndarray, float]) -> None:
    positions, fps = gait
    params = FillParams(confident_error_mm=3.0)
    result = fill_gaps(positions, fps, params, apply="confident")
    for g in result.gaps:
        assert g.applied == g.confident
        assert g.confident == (g.fillable and g.expected_error < 3.0)
        assert result.filled[g.start : g.end + 1, g.marker].all() == g.applied


def test_apply_none_changes_nothing_but_lists_the_gaps(gait: tuple[np.ndarray, float]) -> None:
    positions, fps = gait
    result = fill_gaps(positions, fps, apply="none")
    assert bits(result.positions).tobytes() == bits(positions).tobytes()
    assert not result.filled.any()
    listed = [(g.marker, g.start, g.end) for g in result.gaps]
    assert listed == list(
        zip(*(r.tolist() for r in column_runs(np.isnan(positions[..., 0]))), strict=True)
    )
    assert not any(g.applied for g in result.gaps)
    assert any(g.fillable for g in result.gaps)


@pytest.mark.parametrize("where", ["start", "end"])
def test_gap_at_the_takes_end(cmu: tuple[np.ndarray, float], where: str) -> None:
    positions, fps = cmu
    take = positions[:600]
    n, length = take.shape[0], round(0.3 * fps)
    a, b = (0, length - 1) if where == "start" else (n - length, n - 1)
    assert not np.isnan(take[:, MARKER]).any()
    hidden = hide(take, MARKER, a, b)
    plan = plan_gap(FillContext(hidden, fps, FillParams(), 1.0), MARKER, a, b)
    assert "spline" not in plan.fills
    assert {"rigid", "pca"} <= set(plan.fills)
    truth = take[a : b + 1, MARKER]
    assert rmse(plan.fills["rigid"], truth) < 30.0
    result = fill_gaps(hidden, fps, apply="all")
    (gap,) = [g for g in result.gaps if g.marker == MARKER]
    assert (gap.start, gap.end, gap.method in ("rigid", "pca", "blend")) == (a, b, True)
    assert result.filled[a : b + 1, MARKER].all()


def test_all_missing_marker_is_not_fillable(gait: tuple[np.ndarray, float]) -> None:
    positions, fps = gait
    hidden = positions.copy()
    hidden[:, 7] = np.nan
    result = fill_gaps(hidden, fps, apply="all")
    (gap,) = [g for g in result.gaps if g.marker == 7]
    assert (gap.start, gap.end) == (0, positions.shape[0] - 1)
    assert not gap.fillable
    assert not gap.applied
    assert not gap.confident
    assert gap.method is None
    assert np.isnan(result.positions[:, 7]).all()
    assert not result.filled[:, 7].any()


def test_real_gapped_take_against_its_clean_twin(corpus_dir: Path) -> None:
    gapped, fps = load(corpus_dir / TENNIS_GAPS)
    clean, _ = load(corpus_dir / TENNIS)
    missing = np.isnan(gapped[..., 0])
    assert missing.any()
    assert not np.isnan(clean).any()
    np.testing.assert_array_equal(gapped[~missing], clean[~missing])
    result = fill_gaps(gapped, fps, apply="all", units_per_mm=0.001)
    assert all(g.fillable for g in result.gaps)
    np.testing.assert_array_equal(result.filled, missing)
    error_mm = rmse(result.positions[missing], clean[missing]) * 1000.0
    expected_mm = (
        np.sqrt(
            sum(g.expected_error**2 * (g.end - g.start + 1) for g in result.gaps) / missing.sum()
        )
        * 1000.0
    )
    print(f"tennis serve gaps: fill RMSE {error_mm:.1f} mm, expected {expected_mm:.1f} mm")
    assert error_mm < 25.0


def test_bench_table_rows(corpus_dir: Path) -> None:
    rows = fill_table(corpus_dir, seeds=(0,), files=(GAIT,), events_per_bin=1)
    assert [r["bin"] for r in rows] == ["0.05-0.2", "0.2-0.5", "0.5-1", "1-2"]
    for r in rows:
        assert {"gaps", "spline_mm", "rigid_mm", "pca_mm", "auto_mm", "auto_vs_spline"} <= set(r)


def test_bad_options_raise() -> None:
    positions = np.zeros((10, 4, 3))
    with pytest.raises(OptionError):
        fill_gaps(positions, 100.0, apply="some")  # type: ignore[arg-type]
    with pytest.raises(OptionError):
        fill_gaps(positions, 0.0)
    with pytest.raises(OptionError):
        FillParams(rigid_donors=2)
    with pytest.raises(OptionError):
        FillParams(methods=("spline", "cubic"))
    with pytest.raises(ShapeError):
        fill_gaps(np.zeros((10, 4)), 100.0)
