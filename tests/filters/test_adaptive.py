"""The adaptive blend: the note's rules, innovation weights, streaming and presets."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mocapqa.errors import InputError, ShapeError
from mocapqa.filters.adaptive import (
    AdaptiveFilter,
    AdaptiveParams,
    adaptive_filter,
    rule_weights,
)
from mocapqa.filters.registry import FILTERS, DataScale

CM = DataScale(units_per_metre=100.0, units_per_normalised=200.0, fps=30.0)


def test_rule_weights_follow_the_note() -> None:
    # Rows from the note's section 5.3: slow, normal, fast; then jitter and low confidence.
    p = AdaptiveParams()
    speed = np.array([0.05, 0.5, 2.0, 0.5, 0.5])
    jitter = np.array([0.0, 0.0, 0.0, 0.75, 0.0])
    conf = np.array([1.0, 1.0, 1.0, 1.0, 0.3])
    expected = [
        [0.2, 0.2, 0.6],
        [0.25, 0.55, 0.2],
        [0.5, 0.4, 0.1],
        [0.05, 0.65, 0.3],
        [0.45, 0.45, 0.1],
    ]
    np.testing.assert_allclose(rule_weights(speed, jitter, conf, p), expected, atol=1e-12)


def test_rule_weights_clip_negative_weights_and_sum_to_one() -> None:
    # Slow + jittery: K = 0.2 − 0.2 = 0; still valid weights.
    w = rule_weights(np.array([0.0]), np.array([1.0]), np.array([1.0]), AdaptiveParams())
    assert w.min() >= 0
    assert w.sum() == pytest.approx(1.0)


@settings(max_examples=15, deadline=None)
@given(value=st.floats(-500, 500, allow_nan=False), preset=st.sampled_from(["default", "note"]))
def test_constant_input_comes_back_unchanged(value: float, preset: str) -> None:
    p = FILTERS["adaptive"].preset(preset, CM)
    x = np.full((15, 3, 3), value)
    res = adaptive_filter(x, 30.0, p, np.full((15, 3), 0.8))
    np.testing.assert_allclose(res.values, x, atol=1e-9 * max(1.0, abs(value)))
    np.testing.assert_allclose(res.weights.sum(axis=2), 1.0, atol=1e-12)


@pytest.mark.parametrize("preset", ["default", "note"])
def test_streaming_equals_batch_with_gaps(preset: str) -> None:
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.normal(size=(80, 4, 3)), axis=0)
    conf = rng.uniform(0.1, 1.0, size=(80, 4))
    x[20:26, 1] = np.nan
    conf[20:26, 1] = 0.0
    conf[40, 2] = 0.0
    p = FILTERS["adaptive"].preset(preset, CM)
    batch = adaptive_filter(x, 30.0, p, conf)
    f = AdaptiveFilter(p, 4, 30.0)
    outs = [f.update(x[t], conf[t]) for t in range(80)]
    np.testing.assert_array_equal(np.array([o[0] for o in outs]), batch.values)
    np.testing.assert_array_equal(np.array([o[1] for o in outs]), batch.weights)
    assert not np.isnan(batch.values).any()
    assert batch.bridged[20:26, 1].all()
    assert batch.bridged[40, 2]


def test_innovation_weights_favour_the_filter_that_predicts_best() -> None:
    # A steady ramp: the constant-velocity Kalman predicts it exactly, the EMA lags behind.
    t = np.arange(90) / 30.0
    x = np.stack([np.stack([t, 2 * t, -t], axis=1)] * 2, axis=1) * 100.0
    p = FILTERS["adaptive"].preset("default", CM)
    res = adaptive_filter(x, 30.0, p, np.ones((90, 2)))
    late = res.weights[60:].mean(axis=(0, 1))
    assert late[0] > late[1] > 0
    assert late[0] > late[2]


def test_adaptive_filter_rejects_bad_shapes_and_parameters() -> None:
    f = AdaptiveFilter(AdaptiveParams(), 3, 30.0)
    with pytest.raises(ShapeError, match=r"Expected `frame` to have shape \(3, 3\)"):
        f.update(np.zeros((2, 3)), np.ones(2))
    with pytest.raises(InputError, match="Expected `weighting`"):
        dataclasses.replace(AdaptiveParams(), weighting="vote")  # type: ignore[arg-type]


def test_a_window_longer_than_the_take_costs_the_take_not_the_window() -> None:
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.normal(size=(20, 3, 3)), axis=0)
    p = dataclasses.replace(
        FILTERS["adaptive"].preset("note", CM), weighting="rules", window_s=60.0
    )
    fps = 1000.0  # a 60 s window is 60,000 frames; the take has 20
    batch = adaptive_filter(x, fps, p)
    # Streaming, which cannot know the take's length, keeps the whole window: same output.
    f = AdaptiveFilter(p, 3, fps)
    assert f.state.n_window == 60_000
    outs = [f.update(x[t]) for t in range(20)]
    np.testing.assert_array_equal(np.array([o[0] for o in outs]), batch.values)
    np.testing.assert_array_equal(np.array([o[1] for o in outs]), batch.weights)
    capped = AdaptiveFilter(p, 3, fps, max_frames=20)
    assert capped.state.n_window == 60_000
    assert max(len(a) for a in (capped.state._speeds, capped.state._accels)) == 20


def test_parameters_out_of_range_are_refused_naming_the_range() -> None:
    for name, value in [("window_s", float("inf")), ("window_s", 1e9), ("lead_s", -1.0)]:
        with pytest.raises(InputError, match=f"Expected `{name}` 0"):
            dataclasses.replace(AdaptiveParams(), **{name: value})
    with pytest.raises(InputError, match="Expected `confidence_threshold` 0 to 1, got nan"):
        AdaptiveParams(confidence_threshold=float("nan"))
    # The bounds themselves are valid.
    AdaptiveParams(window_s=60.0, lead_s=0.0, innovation_power=10.0, jitter_threshold=1.0)
