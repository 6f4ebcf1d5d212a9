"""The plotted frames keep every peak, the ends, the kept frames and the gaps, within the limit."""

from __future__ import annotations

import numpy as np
import pytest

from mocapqa.core.decimate import bucket_extremes, peak_frames, sample_frames
from mocapqa.errors import InputError


def spiky(rng: np.random.Generator, n_frames: int, n_spikes: int) -> tuple[np.ndarray, np.ndarray]:
    """A noisy slow wave with one-frame spikes (up or down) at random frames 300+ apart.

    The spikes are farther apart than a bucket (about 170 frames below), so each is the extreme
    of its own bucket; two spikes of one sign in one bucket keep the larger only.
    """
    slots = rng.choice(n_frames // 500 - 1, size=n_spikes, replace=False) + 1
    spikes = np.sort(slots * 500 + rng.integers(-100, 101, size=n_spikes))
    t = np.arange(n_frames)
    signal = 30 * np.sin(2 * np.pi * t / 900) + rng.normal(0, 0.5, n_frames)
    signal[spikes] += rng.choice([-1.0, 1.0], size=n_spikes) * rng.uniform(40, 120, n_spikes)
    return signal, spikes


@pytest.mark.parametrize("seed", range(5))
def test_every_one_frame_spike_is_kept_far_below_the_frame_count(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n_frames, max_points = 50_000, 1_500
    first, spikes_a = spiky(rng, n_frames, 40)
    second, spikes_b = spiky(rng, n_frames, 40)
    frames = peak_frames(np.stack([first, second], axis=1), max_points)
    assert len(frames) <= max_points
    assert np.all(np.diff(frames) > 0)
    assert frames[0] == 0
    assert frames[-1] == n_frames - 1
    assert np.isin(spikes_a, frames).all()
    assert np.isin(spikes_b, frames).all()
    # The stride it replaces drops most of them.
    assert np.isin(spikes_a, sample_frames(n_frames, max_points)).mean() < 0.5


SIZES = [(2001, 2000, 3), (10_000, 10, 4), (10_000, 2000, 0), (7, 2, 1)]


@pytest.mark.parametrize(("n_frames", "max_points", "n_series"), SIZES)
def test_the_ends_are_kept_and_the_limit_holds(
    n_frames: int, max_points: int, n_series: int
) -> None:
    signals = np.random.default_rng(1).normal(size=(n_frames, n_series))
    frames = peak_frames(signals, max_points, np.arange(0, n_frames, 3))
    assert frames[0] == 0
    assert frames[-1] == n_frames - 1
    assert len(frames) <= max_points
    assert np.all(np.diff(frames) > 0)


def test_a_short_take_keeps_every_frame() -> None:
    signals = np.random.default_rng(2).normal(size=(300, 5))
    np.testing.assert_array_equal(peak_frames(signals, 300), np.arange(300))
    np.testing.assert_array_equal(peak_frames(signals, 2000), np.arange(300))


def test_a_gap_stays_a_gap() -> None:
    rng = np.random.default_rng(3)
    signal = np.cumsum(rng.normal(size=20_000))
    gaps = [(1_000, 1_000), (5_003, 5_040), (12_345, 12_346), (19_990, 19_998)]
    for a, b in gaps:
        signal[a : b + 1] = np.nan
    frames = peak_frames(signal[:, None], 500)
    assert len(frames) <= 500
    for a, b in gaps:  # each gap holds a kept frame, so no line is drawn across it
        assert np.any((frames >= a) & (frames <= b)), (a, b)
    # A series missing everywhere still gives the ends and stays within the limit.
    empty = peak_frames(np.full((5_000, 2), np.nan), 100)
    assert (empty[0], empty[-1]) == (0, 4_999)
    assert len(empty) <= 100


def test_kept_frames_come_first_most_important_first() -> None:
    n_frames, max_points = 10_000, 100
    signals = np.zeros((n_frames, 1))
    wanted = np.array([7_001, 13, 4_242, -5, n_frames + 3])
    frames = peak_frames(signals, max_points, wanted)
    assert np.isin([7_001, 13, 4_242], frames).all()
    # More than fit: the first ones are kept, within the limit.
    many = np.arange(1, n_frames - 1)[::-1]
    frames = peak_frames(signals, max_points, many)
    assert len(frames) == max_points
    assert np.isin(many[: max_points - 2], frames).all()


def test_bucket_extremes_are_the_lowest_highest_and_first_missing() -> None:
    signal = np.array([[3.0], [1.0], [np.nan], [5.0], [2.0], [2.0], [9.0], [0.0]])
    # Buckets [0, 4) and [4, 8): firsts 0 and 4; lows 1 and 7; highs 3 and 6; gap 2.
    np.testing.assert_array_equal(bucket_extremes(signal, 4), [0, 1, 2, 3, 4, 6, 7])
    with pytest.raises(InputError, match="width"):
        bucket_extremes(signal, 0)
    with pytest.raises(InputError, match="max_points"):
        peak_frames(signal, 1)
