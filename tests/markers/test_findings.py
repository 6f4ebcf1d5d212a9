"""Gaps, spikes, segments, swaps and labels on small arrays and on real takes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import butter, filtfilt
from tests.markers.conftest import Take

from mocapqa.errors import InputError, OptionError, ShapeError
from mocapqa.markers.check import check_markers
from mocapqa.markers.gaps import find_gaps, summarise_gaps
from mocapqa.markers.inject import inject_swaps
from mocapqa.markers.labels import base_label, find_label_problems
from mocapqa.markers.params import MarkerParams
from mocapqa.markers.segments import infer_segments, pair_stats
from mocapqa.markers.spikes import find_spikes
from mocapqa.markers.swap_repair import repair_swaps, select_swaps
from mocapqa.markers.swaps import Swap


def _swap(a: int, b: int, start: int, end: int, confidence: float) -> Swap:
    return Swap((f"M{a}", f"M{b}"), (a, b), start, end, confidence, 9.0, 0.5, (True, True),
                "error")  # fmt: skip


def test_gaps_are_runs_of_missing_samples_with_their_length_and_severity() -> None:
    present = np.ones((100, 2), dtype=bool)
    present[0:3, 0] = False  # at the start: an edge gap
    present[40:70, 0] = False  # 0.5 s at 60 fps: an error
    present[10:12, 1] = False
    gaps = find_gaps(present, ("A", "B"), 60.0)
    assert [(g.marker, g.start, g.end, g.frames, g.edge, g.severity) for g in gaps] == [
        ("A", 0, 2, 3, True, "info"),
        ("A", 40, 69, 30, False, "error"),
        ("B", 10, 11, 2, False, "info"),
    ]
    summary = summarise_gaps(present, ("A", "B"), 60.0)
    assert (summary[0].count, summary[0].longest) == (2, 30)
    assert summary[0].missing == pytest.approx(0.33)
    assert summary[0].longest_s == pytest.approx(0.5)


def test_a_fast_smooth_serve_is_not_a_spike_and_one_bad_sample_is(
    clean_takes: dict[str, Take],
) -> None:
    take = clean_takes["optitrack/kinematics_tennis_serve.c3d"]
    # The serve low-passed at 10 Hz keeps its speed (the wrist still moves at metres per
    # second) but loses the take's tracking glitches.
    b, a = butter(2, 10.0 / (take.fps / 2))
    smooth = filtfilt(b, a, take.positions, axis=0)
    wrist = take.names.index("Derrick:RWRA")
    speed = np.linalg.norm(np.diff(smooth[:, wrist], axis=0), axis=1) * take.fps
    assert speed.max() > 10.0  # m/s
    assert find_spikes(smooth, take.names, take.fps, take.length_unit) == []
    bad = smooth.copy()
    bad[500, wrist] += [0.0, 0.03, 0.0]  # 3 cm off for one frame
    [spike] = find_spikes(bad, take.names, take.fps, take.length_unit)
    assert (spike.marker, spike.peak) == ("Derrick:RWRA", 500)
    assert spike.start >= 498
    assert spike.end <= 502
    assert spike.offset == pytest.approx(0.03, rel=0.2)


def test_segments_group_markers_of_one_body_part(clean_takes: dict[str, Take]) -> None:
    take = clean_takes["cmu/cmu_02_05.c3d"]
    segments = infer_segments(pair_stats(take.positions, take.length_unit), take.names)
    named = {s.name: {base_label(m) for m in s.markers} for s in segments}
    assert named["head"] == {"LFHD", "RFHD", "LBHD", "RBHD"}
    assert named["pelvis"] == {"LFWT", "RFWT", "LBWT", "RBWT"}
    members = [m for s in segments for m in s.markers]
    assert len(members) == len(set(members))


def test_repair_exchanges_the_two_labels_over_the_interval_only() -> None:
    positions = np.arange(10 * 3 * 3, dtype=np.float64).reshape(10, 3, 3)
    repaired = repair_swaps(positions, [_swap(0, 2, 4, 6, 0.9)])
    np.testing.assert_array_equal(repaired[4:7, 0], positions[4:7, 2])
    np.testing.assert_array_equal(repaired[4:7, 2], positions[4:7, 0])
    np.testing.assert_array_equal(repaired[:4], positions[:4])
    np.testing.assert_array_equal(repaired[7:], positions[7:])
    np.testing.assert_array_equal(repaired[:, 1], positions[:, 1])
    np.testing.assert_array_equal(repair_swaps(repaired, [_swap(0, 2, 4, 6, 0.9)]), positions)
    residuals = np.arange(30, dtype=np.float64).reshape(10, 3)
    assert repair_swaps(residuals, [_swap(0, 1, 0, 0, 0.9)])[0].tolist() == [1.0, 0.0, 2.0]
    with pytest.raises(InputError, match="inside 10 frames"):
        repair_swaps(positions, [_swap(0, 1, 8, 10, 0.9)])


def test_the_apply_rule_picks_confident_all_or_no_swaps() -> None:
    swaps = [_swap(0, 1, 0, 3, 0.95), _swap(2, 3, 5, 8, 0.6)]
    params = MarkerParams(swap_confidence=0.8)
    assert select_swaps(swaps, "confident", params) == swaps[:1]
    assert select_swaps(swaps, "all", params) == swaps
    assert select_swaps(swaps, "none", params) == []
    with pytest.raises(OptionError, match="apply"):
        select_swaps(swaps, "some", params)


def test_injected_swaps_pair_neighbours_in_complete_stretches(
    clean_takes: dict[str, Take],
) -> None:
    take = clean_takes["vicon/nick_freeform_001.c3d"]
    stats = pair_stats(take.positions, take.length_unit)
    swapped, truth = inject_swaps(take.positions, np.random.default_rng(7), stats, take.fps, 3)
    assert len(truth) == 3
    for t in truth:
        assert 6 <= t.end - t.start + 1 <= 120  # 0.05–1 s at 120 fps
        window = slice(t.start, t.end + 1)
        assert np.isfinite(take.positions[window][:, [t.a, t.b]]).all()
        np.testing.assert_array_equal(swapped[window, t.a], take.positions[window, t.b])
        assert stats.median[t.a, t.b] < 400.0  # neighbours, mm
    assert len({m for t in truth for m in (t.a, t.b)}) == 6
    with pytest.raises(InputError, match="room for 500 swaps"):
        inject_swaps(take.positions, np.random.default_rng(7), stats, take.fps, 500)


def test_labels_are_compared_without_the_subject_and_the_reader_s_repeat_suffix() -> None:
    found = find_label_problems(["A:LANK", "B:LANK", "S:RANK", "RANK", "X", "X#2", "",
                                 "Unlabeled 1000", "C_3", "*7", "New 0001", "RTOE"])  # fmt: skip
    assert [(f.kind, f.names) for f in found] == [
        ("unlabelled", ("",)),
        ("unlabelled", ("Unlabeled 1000",)),
        ("unlabelled", ("C_3",)),
        ("unlabelled", ("*7",)),
        ("unlabelled", ("New 0001",)),
        ("duplicate", ("S:RANK", "RANK")),
        ("duplicate", ("X", "X#2")),
    ]


def test_bad_inputs_and_parameters_are_refused() -> None:
    with pytest.raises(ShapeError, match=r"\(F, M, 3\)"):
        check_markers(np.zeros((10, 3)), ["a", "b", "c"], 60.0, "mm")
    with pytest.raises(ShapeError, match="3 marker names"):
        check_markers(np.zeros((10, 3, 3)), ["a"], 60.0, "mm")
    with pytest.raises(InputError, match="fps"):
        check_markers(np.zeros((10, 1, 3)), ["a"], 0.0, "mm")
    with pytest.raises(OptionError, match="swap_confidence"):
        MarkerParams(swap_confidence=1.5)
    with pytest.raises(OptionError, match="gap_error_s"):
        MarkerParams(gap_warning_s=1.0, gap_error_s=0.5)
    with pytest.raises(OptionError, match="spike_ratio"):
        MarkerParams(spike_ratio=float("nan"))


def test_tiny_and_empty_takes_check_without_findings() -> None:
    report = check_markers(np.zeros((1, 2, 3)), ["a", "b"], 50.0, "mm")
    assert report.swaps == ()
    assert report.spikes == ()
    assert report.gaps == ()
    empty = check_markers(np.full((4, 1, 3), np.nan), ["a"], 50.0, "m")
    assert [(s.marker, s.kind) for s in empty.static] == [("a", "absent")]
    assert [(g.start, g.end) for g in empty.gaps] == [(0, 3)]
