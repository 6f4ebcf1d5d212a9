"""The analysis JSON shape, the metrics and the docstring coverage of the twist modules."""

from __future__ import annotations

import importlib
from typing import get_origin

import numpy as np
import pytest

from mocapqa.core.motion import Motion
from mocapqa.metrics.twist import twist_accuracy
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.inject import inject_twist_errors

MODULES = [
    "mocapqa.twist.angles",
    "mocapqa.twist.detect",
    "mocapqa.twist.refine",
    "mocapqa.twist.inject",
    "mocapqa.twist.inject_unpaired",
    "mocapqa.twist.outside",
    "mocapqa.twist.analysis",
    "mocapqa.metrics.twist",
    "mocapqa_bench.twist",
    "mocapqa_bench.unpaired",
    "mocapqa.cli.twist",
]


def test_to_json_has_the_documented_shape(takes: dict[str, Motion]) -> None:
    corrupted, truth = inject_twist_errors(takes["cmu"], np.random.default_rng(9))
    analysis = analyze_twist(corrupted)
    data = analysis.to_json()
    assert data["n_frames"] == corrupted.n_frames
    assert data["frame_step"] == 1
    assert len(data["frames"]) == corrupted.n_frames
    assert len(data["chains"]) == 10
    for chain in data["chains"]:
        assert set(chain) >= {"joint", "child", "side", "segment", "axis", "theta_p_deg",
                              "offset_deg", "flagged", "intervals"}  # fmt: skip
        assert len(chain["theta_p_deg"]) == len(chain["offset_deg"]) == len(chain["flagged"])
    flagged = {c["joint"]: sum(c["flagged"]) for c in data["chains"]}
    for name in {i.joint for i in truth.intervals}:
        assert flagged[name] > 0
    assert {tuple(sorted(i)) for i in data["intervals"]} == {
        tuple(sorted(i.to_json())) for i in analysis.intervals
    }


def test_to_json_decimates_long_takes_and_keeps_one_frame_intervals(
    takes: dict[str, Motion],
) -> None:
    corrupted, _ = inject_twist_errors(takes["cmu"], np.random.default_rng(9))
    analysis = analyze_twist(corrupted)
    full = analysis.to_json()
    short = analysis.to_json(max_points=100)
    frames = np.asarray(short["frames"])
    assert len(frames) <= 100
    assert short["frame_step"] == np.diff(frames).max() > 1
    # Every interval's first frame and every offset step are kept.
    assert np.isin(analysis.step_frames(), frames).all()
    for a, b in zip(full["chains"], short["chains"], strict=True):
        assert len(b["offset_deg"]) == len(b["theta_p_deg"]) == len(frames)
        assert (sum(a["flagged"]) > 0) == (sum(b["flagged"]) > 0)
        # Each series is its value at the kept frames, and keeps its extremes.
        for key in ("theta_p_deg", "offset_deg"):
            np.testing.assert_array_equal(np.asarray(a[key])[frames], b[key])
            assert (min(b[key]), max(b[key])) == (min(a[key]), max(a[key]))


def test_twist_accuracy_matches_hand_computed_values() -> None:
    # before 100, 50, 10 degrees; after 10 (90 % less), 20 (60 % less), 2 (80 % less).
    accuracy = twist_accuracy(np.array([100.0, 50.0, 10.0]), np.array([10.0, 20.0, 2.0]))
    assert accuracy.n_success == 2
    assert accuracy.fsr == pytest.approx(2 / 3)
    assert accuracy.mae_before_deg == pytest.approx(160 / 3)
    assert accuracy.mae_after_deg == pytest.approx(32 / 3)
    assert accuracy.rmse_after_deg == pytest.approx(np.sqrt((100 + 400 + 4) / 3))
    assert accuracy.rer == pytest.approx(32 / 160)


@pytest.mark.parametrize("name", MODULES)
def test_every_public_name_has_a_docstring(name: str) -> None:
    module = importlib.import_module(name)
    assert module.__doc__
    for public in module.__all__:
        obj = getattr(module, public)
        # Type aliases (``Method = Literal[...]``) carry their docstring in the source only.
        if get_origin(obj) is None and (callable(obj) or isinstance(obj, type)):
            assert obj.__doc__, f"{name}.{public} has no docstring"
