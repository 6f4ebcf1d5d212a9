"""The live stream session filters like the batch filter on the same frames."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError
from mocapqa.filters.apply import filter_keypoints
from mocapqa.io.formats import read_take
from mocapqa.pipeline.filtering import StreamSession

TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


@pytest.fixture(scope="module")
def trc_take(corpus_dir: Path) -> KeypointSequence:
    take = read_take(corpus_dir / TRC)
    assert isinstance(take, KeypointSequence)
    return take


@pytest.mark.parametrize("preset", ["default", "note"])
def test_stream_equals_batch_filter_with_the_same_preset(
    trc_take: KeypointSequence, preset: str
) -> None:
    seq = trc_take
    rng = np.random.default_rng(5)
    confidence = rng.uniform(0.2, 1.0, seq.confidence.shape)
    noisy = seq.positions + rng.normal(0.0, 0.01, seq.positions.shape)
    seq = KeypointSequence(
        names=seq.names,
        positions=noisy,
        confidence=confidence,
        fps=seq.fps,
        length_unit=seq.length_unit,
    )
    session = StreamSession(seq.fps, seq.n_keypoints, seq.length_unit, preset)
    streamed = np.stack(
        [session.filter(seq.positions[t], seq.confidence[t])[0] for t in range(seq.n_frames)]
    )
    batch = filter_keypoints(seq, method="adaptive", preset=preset)
    np.testing.assert_allclose(streamed, batch.sequence.positions, rtol=0, atol=1e-12)
    # The preset matters: the seed note's parameters give a different output.
    other = "note" if preset == "default" else "default"
    different = filter_keypoints(seq, method="adaptive", preset=other).sequence.positions
    assert np.abs(streamed - different).max() > 1e-4


def test_stream_refuses_unknown_units_and_presets() -> None:
    with pytest.raises(InputError, match="Expected a length unit"):
        StreamSession(30.0, 4, "furlong")
    with pytest.raises(InputError, match="Expected a preset"):
        StreamSession(30.0, 4, "m", "fastest")
    session = StreamSession(30.0, 4, "px")
    with pytest.raises(InputError, match="Expected metric units"):
        session.filter(np.full((4, 3), np.nan), None)


@pytest.mark.parametrize("fps", [1e-300, 0.05, 100_001.0, float("inf"), float("nan")])
def test_stream_refuses_a_frame_rate_out_of_bounds(fps: float) -> None:
    """1e-300 fps was a session whose first frame overflowed the Kalman filter's dt⁴."""
    with pytest.raises(InputError, match=r"at least 0\.1 and at most 100000"):
        StreamSession(fps, 4, "m")


@pytest.mark.parametrize("unit", ["m", "unknown"])
def test_stream_refuses_coordinates_and_confidences_out_of_bounds(unit: str) -> None:
    """Positions of 1e308 were a ZeroDivisionError (the body size of a first frame) or
    infinity out of the filter."""
    session = StreamSession(30.0, 2, unit)
    with pytest.raises(InputError, match="within ±1,000,000,000"):
        session.filter(np.full((2, 3), 1e308), None)
    with pytest.raises(InputError, match="within ±1,000,000,000"):
        session.filter(np.array([[np.inf, 0, 0], [1, 2, 3]]), None)
    with pytest.raises(InputError, match="from 0 to 1"):
        session.filter(np.zeros((2, 3)), np.array([2.0, 1.0]))
    assert session.frame == 0
    filtered, _ = session.filter(np.array([[1e9, -1e9, 0], [np.nan, 2, 3]]), np.array([1, 0.0]))
    assert session.frame == 1
    assert np.isfinite(filtered[0]).all()
