"""Marker takes cost bounded memory: the pair statistics computed a block of markers at a time
equal the former whole-array computation, and a take of more markers than ``max_markers`` is
refused from its header, before it is parsed (413 through the API)."""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import make_settings
from tests.markers.conftest import Take

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.core.arrays import FloatArray
from mocapqa.errors import TooLargeError
from mocapqa.io.formats import read_take
from mocapqa.io.guards import ReadLimits, check_take_input
from mocapqa.markers import segments
from mocapqa.markers.params import MarkerParams, unit_scale
from mocapqa.markers.segments import PairStats, pair_stats


def _whole_array_stats(positions: FloatArray, length_unit: str, params: MarkerParams) -> PairStats:
    """The statistics from one ``(S, M, M)`` array of distances (the former computation)."""
    n_frames, n_markers = positions.shape[:2]
    limit = params.segment_frames
    if n_frames <= limit:
        frames = np.arange(n_frames)
    else:
        frames = np.unique(np.linspace(0, n_frames - 1, limit).round().astype(np.intp))
    sampled = positions[frames]
    diff = sampled[:, :, None, :] - sampled[:, None, :, :]
    distances = np.sqrt(np.einsum("smnk,smnk->smn", diff, diff))
    counts = np.isfinite(distances).sum(axis=0)
    ordered = np.sort(distances, axis=0)

    def percentile(q: float) -> FloatArray:
        index = np.clip(np.round(q * (counts - 1)).astype(np.intp), 0, None)
        value: FloatArray = np.take_along_axis(ordered, index[None], axis=0)[0]
        return np.where(counts > 0, value, np.nan)

    median = percentile(0.5)
    spread = percentile(0.9) - percentile(0.1)
    threshold = params.rigid_spread * unit_scale(length_unit) + params.rigid_relative * median
    enough = counts >= max(2, params.rigid_min_visible * sampled.shape[0])
    off_diagonal = ~np.eye(n_markers, dtype=bool)
    with np.errstate(invalid="ignore"):
        rigid = enough & off_diagonal & (spread <= threshold)
    median = np.where(off_diagonal & enough, median, np.nan)
    spread = np.where(off_diagonal & enough, spread, np.nan)
    return PairStats(median, spread, threshold, rigid)


def _assert_identical(got: PairStats, expected: PairStats) -> None:
    for name in ("median", "spread", "threshold", "rigid"):
        a, b = getattr(got, name), getattr(expected, name)
        assert a.shape == b.shape, name
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name


@pytest.mark.parametrize("block", [1, 700, 5_000, 1 << 21])
def test_blocked_stats_equal_the_whole_array_on_a_real_take(
    clean_takes: dict[str, Take], block: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    take = clean_takes["cmu/cmu_02_05.c3d"]
    params = MarkerParams(segment_frames=200)
    expected = _whole_array_stats(take.positions, take.length_unit, params)
    assert expected.rigid.any()  # the take has rigid pairs to find
    monkeypatch.setattr(segments, "_BLOCK_VALUES", block)
    _assert_identical(pair_stats(take.positions, take.length_unit, params), expected)


@pytest.mark.parametrize("block", [1, 333, 4_096])
def test_blocked_stats_equal_the_whole_array_on_random_data_with_gaps(
    block: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(7)
    n_frames, n_markers = 80, 37
    # Rigid groups of four (a marker per group plus small noise) and free markers.
    base = rng.normal(size=(n_frames, n_markers // 4 + 1, 3)) * 400.0
    positions = (
        np.repeat(base, 4, axis=1)[:, :n_markers]
        + rng.normal(size=(n_frames, n_markers, 3))
        * np.where(np.arange(n_markers) % 3 == 0, 200.0, 1.0)[None, :, None]
    )
    positions[rng.random((n_frames, n_markers)) < 0.2] = np.nan
    positions[:, 5] = np.nan  # a marker never seen
    positions[:70, 6] = np.nan  # one seen on too few frames
    params = MarkerParams(segment_frames=50)
    expected = _whole_array_stats(positions, "mm", params)
    assert expected.rigid.any()
    assert not expected.rigid.all()
    monkeypatch.setattr(segments, "_BLOCK_VALUES", block)
    _assert_identical(pair_stats(positions, "mm", params), expected)


def test_pair_stats_memory_stays_bounded_for_many_markers() -> None:
    rng = np.random.default_rng(0)
    n_frames, n_markers = 100, 1000
    positions = rng.normal(size=(n_frames, n_markers, 3)) * 300.0
    tracemalloc.start()
    try:
        stats = pair_stats(positions, "mm")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert stats.median.shape == (n_markers, n_markers)
    # One (S, M, M) float64 array alone would be 800 MB; the blocks hold about 64 MB.
    assert peak < 200e6, f"peak {peak / 1e6:.0f} MB"


def trc_bytes(n_frames: int, n_markers: int, newline: str = "\n") -> bytes:
    """A valid TRC of random positions (metres)."""
    rng = np.random.default_rng(n_markers)
    positions = rng.normal(size=(n_frames, n_markers, 3))
    lines = [
        "PathFileType\t4\t(X/Y/Z)\ttake.trc",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
        "\tOrigNumFrames",
        f"60\t60\t{n_frames}\t{n_markers}\tm\t60\t1\t{n_frames}",
        "Frame#\tTime\t" + "\t\t\t".join(f"M{m}" for m in range(n_markers)),
        "\t\t" + "\t".join(f"X{m}\tY{m}\tZ{m}" for m in range(1, n_markers + 1)),
    ]
    lines += [
        f"{f + 1}\t{f / 60:.5f}\t" + "\t".join(f"{v:.4f}" for v in positions[f].ravel())
        for f in range(n_frames)
    ]
    return (newline.join(lines) + newline).encode()


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"])
def test_the_marker_limit_is_exact_on_a_trc(tmp_path: Path, newline: str) -> None:
    path = tmp_path / "many.trc"
    path.write_bytes(trc_bytes(5, 51, newline))
    check_take_input(path, "trc", ReadLimits(max_markers=51))
    with pytest.raises(TooLargeError) as refused:
        check_take_input(path, "trc", ReadLimits(max_markers=50))
    assert str(refused.value) == (
        "many.trc: Expected at most 50 markers (setting max_markers), got 51"
    )
    assert read_take(path, limits=ReadLimits(max_markers=51)).n_keypoints == 51


def test_the_marker_limit_is_exact_on_a_c3d(c3d_dir: Path) -> None:
    path = c3d_dir / "btk" / "PiG_Motion-FlatFoot-Full.c3d"
    assert read_take(path, limits=ReadLimits(max_markers=193)).n_keypoints == 193
    with pytest.raises(TooLargeError, match=r"PiG_Motion-FlatFoot-Full\.c3d: .*max_markers"):
        read_take(path, limits=ReadLimits(max_markers=192))


def test_every_real_marker_take_is_far_under_the_default_limit(corpus_dir: Path) -> None:
    """Every C3D and TRC of the corpus passes a fifth of the default (the largest has 193
    points: Plug-in Gait's markers, angles, forces and moments)."""
    fifth = ReadLimits(max_markers=ReadLimits().max_markers // 5)
    takes = [p for p in sorted(corpus_dir.rglob("*")) if p.suffix.lower() in (".c3d", ".trc")]
    read = 0
    for path in takes:
        if path.stat().st_size == 0:
            continue  # an empty file is refused for that, not for its size
        check_take_input(path, path.suffix.lower()[1:], fifth)
        read += 1
    assert read >= 20


def test_the_setting_reaches_the_readers(monkeypatch: pytest.MonkeyPatch) -> None:
    assert Settings().read_limits.max_markers == ReadLimits().max_markers == 1000
    monkeypatch.setenv("MOCAPQA_MAX_MARKERS", "250")
    assert Settings().read_limits.max_markers == 250


def test_an_upload_of_too_many_markers_is_413_before_it_is_stored(tmp_path: Path) -> None:
    """The hostile take: valid, random positions, more markers than the limit."""
    settings = make_settings("sqlite", tmp_path)
    limit = settings.max_markers
    with TestClient(create_app(settings)) as client:
        data = trc_bytes(20, limit + 1)
        response = client.post("/api/v1/takes", files={"file": ("crowd.trc", data)})
        assert response.status_code == 413, response.text
        detail = str(response.json()["detail"])
        assert "max_markers" in detail
        assert "crowd.trc" in detail
        assert str(limit + 1) in detail
        assert client.get("/api/v1/takes").json()["items"] == []
