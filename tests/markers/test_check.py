"""The marker check on real C3D takes: clean takes, the gapped twin, injected swaps, labels and
static markers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tests.markers.conftest import CLEAN_TAKES, Take, load_take

from mocapqa.core.arrays import column_runs
from mocapqa.markers.check import check_markers
from mocapqa.markers.inject import inject_swaps
from mocapqa.markers.segments import pair_stats
from mocapqa.markers.swap_repair import repair_swaps


@pytest.mark.parametrize("name", CLEAN_TAKES)
def test_clean_takes_have_no_swap_and_few_spikes(clean_takes: dict[str, Take], name: str) -> None:
    take = clean_takes[name]
    report = check_markers(take.positions, take.names, take.fps, take.length_unit)
    assert report.swaps == ()
    # The tennis serve's arms have real tracking glitches of 2–10 cm (50 Hz, metres): 18, one
    # per 60 frames. The CMU take has 3 (LBHD 27 mm), the Vicon take none.
    assert len(report.spikes) <= report.frames / 50
    data = report.to_json()
    assert {"gaps", "swaps", "spikes", "segments", "static", "labels"} <= data.keys()


def test_the_gapped_twin_s_gap_table_is_exactly_its_missing_samples(c3d_dir: Path) -> None:
    clean = load_take(c3d_dir / "optitrack" / "kinematics_tennis_serve.c3d")
    gapped = load_take(c3d_dir / "optitrack" / "kinematics_tennis_serve_nan.c3d")
    removed = np.isfinite(clean.positions).all(-1) & ~np.isfinite(gapped.positions).all(-1)
    markers, starts, ends = column_runs(removed)
    report = check_markers(gapped.positions, gapped.names, gapped.fps, gapped.length_unit)
    assert [(g.marker, g.start, g.end) for g in report.gaps] == [
        (gapped.names[m], s, e) for m, s, e in zip(markers, starts, ends, strict=True)
    ]
    assert {g.marker for g in report.gaps} == {"Derrick:RSHO"}
    summary = {s.marker: s for s in report.gap_summary}["Derrick:RSHO"]
    assert summary.count == len(report.gaps) == 10
    assert summary.longest == max(g.frames for g in report.gaps)
    assert summary.missing == pytest.approx(removed.sum() / removed.shape[0])
    first = report.gaps[0]
    assert (first.start, first.end, first.frames) == (134, 147, 14)
    assert first.seconds == pytest.approx(14 / 50)


@pytest.mark.parametrize(
    ("name", "seeds"),
    [
        ("cmu/cmu_02_05.c3d", range(3)),
        ("vicon/nick_freeform_001.c3d", range(3)),
        ("optitrack/kinematics_tennis_serve.c3d", range(3)),
    ],
)
def test_injected_swaps_are_found_and_repaired(
    clean_takes: dict[str, Take], name: str, seeds: range
) -> None:
    take = clean_takes[name]
    stats = pair_stats(take.positions, take.length_unit)
    for seed in seeds:
        swapped, truth = inject_swaps(
            take.positions, np.random.default_rng(seed), stats, take.fps, count=2
        )
        report = check_markers(swapped, take.names, take.fps, take.length_unit)
        assert len(report.swaps) == len(truth), (seed, report.swaps, truth)
        for swap, injected in zip(report.swaps, truth, strict=True):
            assert set(swap.indices) == {injected.a, injected.b}
            assert abs(swap.start - injected.start) <= 2
            assert abs(swap.end - injected.end) <= 2
            assert 0.0 <= swap.confidence <= 1.0
        repaired = repair_swaps(swapped, report.swaps)
        if all(
            (s.start, s.end) == (t.start, t.end) for s, t in zip(report.swaps, truth, strict=True)
        ):
            np.testing.assert_array_equal(repaired, take.positions)


def test_duplicate_and_unlabelled_trajectories_are_reported(
    clean_takes: dict[str, Take],
) -> None:
    take = clean_takes["cmu/cmu_02_05.c3d"]
    names = list(take.names)
    names[5] = "RBWT"  # the same label as TakeoMonday:RBWT once the subject is trimmed
    names[7] = "*12"
    report = check_markers(take.positions, names, take.fps, take.length_unit)
    kinds = {(f.kind, f.names) for f in report.labels}
    assert ("duplicate", ("TakeoMonday:RBWT", "RBWT")) in kinds
    assert ("unlabelled", ("*12",)) in kinds
    data = report.to_json()["labels"]
    assert {"kind": "duplicate", "label": "RBWT", "markers": ["TakeoMonday:RBWT", "RBWT"],
            "severity": "error"} in data  # fmt: skip


def test_a_static_and_an_absent_marker_are_reported(clean_takes: dict[str, Take]) -> None:
    take = clean_takes["vicon/nick_freeform_001.c3d"]
    positions = take.positions.copy()
    rng = np.random.default_rng(3)
    positions[:, 1] = np.array([250.0, -40.0, 12.0]) + rng.normal(0.0, 0.1, (len(positions), 3))
    report = check_markers(positions, take.names, take.fps, take.length_unit)
    static = {(s.marker, s.kind) for s in report.static}
    assert ("Nick01:LFHD", "static") in static
    # CLAV is never seen in this take.
    assert ("Nick01:CLAV", "absent") in static
    assert len(static) == 2
