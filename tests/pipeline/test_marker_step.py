"""The run's markers step: marker takes checked, swaps repaired before gaps are filled, every
filled sample marked in the run's outputs, and the findings counted in the QA summary."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.io.c3d import read_c3d
from mocapqa.io.formats import read_take
from mocapqa.jobs.run_outputs import write_outputs
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.marker_step import MARKER_FINDING_KINDS, run_markers
from mocapqa.pipeline.options import AnalysisOptions, describe_options, take_checks
from mocapqa.pipeline.summary import MARKER_FIELDS, qa_summary
from mocapqa.store.files import FileStore

GAPPED = Path("c3d/optitrack/kinematics_tennis_serve_nan.c3d")
CLEAN = Path("c3d/optitrack/kinematics_tennis_serve.c3d")
RUN_ID = "0123456789abcdef0123456789abcdef"
SHARED = ("kind", "joint", "start_frame", "end_frame", "value", "unit", "confidence")


@pytest.fixture(scope="module")
def clean(corpus_dir: Path) -> KeypointSequence:
    take = read_take(corpus_dir / CLEAN)
    assert isinstance(take, KeypointSequence)
    return take


def test_marker_formats_run_the_markers_check_and_the_form_says_so() -> None:
    assert take_checks("keypoints", "c3d") == ("markers", "feet", "filter")
    assert take_checks("keypoints", "trc") == ("markers", "feet", "filter")
    assert take_checks("keypoints", "openpose") == ("feet", "filter")
    assert "markers" not in take_checks("motion")
    described = describe_options()
    assert described["take_checks"]["markers"] == ["markers", "feet", "filter"]
    assert "c3d" in described["marker_formats"]
    assert "markers" in AnalysisOptions().checks


def test_a_gapped_c3d_run_fills_confident_gaps_and_marks_them(
    corpus_dir: Path, tmp_path: Path
) -> None:
    source = corpus_dir / GAPPED
    take = read_take(source)
    result = analyze(take, AnalysisOptions(checks=("markers",)))
    report = result.report
    assert report["steps"]["markers"]["state"] == "done"
    findings = report["findings"]
    assert findings
    assert all(set(SHARED) <= set(f) for f in findings)
    assert {f["kind"] for f in findings} <= set(MARKER_FINDING_KINDS)
    filled = [f for f in findings if f["kind"] == "gap"]
    left = [f for f in findings if f["kind"] == "gap not filled"]
    assert filled
    assert left
    assert all(f["applied"] and f["unit"] == "mm" and f["value"] < 5 for f in filled)
    assert all(not f["applied"] for f in left)
    # The mask holds exactly the filled gaps' samples; every other sample is as read.
    assert result.markers is not None
    mask = result.markers.filled
    assert mask.sum() == sum(f["end_frame"] - f["start_frame"] + 1 for f in filled)
    names = list(take.names)
    for f in filled:
        assert mask[f["start_frame"] : f["end_frame"] + 1, names.index(f["joint"])].all()
    raw = take.positions
    assert np.array_equal(result.corrected_points[~mask], raw[~mask], equal_nan=True)
    assert np.isfinite(result.corrected_points[mask]).all()
    assert report["points"]["bones"]  # the segments' sticks
    json.dumps(report, allow_nan=False)

    files = FileStore(tmp_path)
    kinds = write_outputs(files, RUN_ID, result, source)
    assert "c3d" in kinds
    folder = files.run_dir(RUN_ID)
    with np.load(folder / "points.npz") as points:
        assert np.array_equal(points["filled"], mask)
    written = read_c3d(folder / "corrected.c3d")
    original = read_c3d(source)
    assert written.points.names == original.points.names
    assert np.all(written.residuals[mask] == 0)
    assert np.allclose(written.points.positions[mask], result.corrected_points[mask], atol=1e-4)
    kept = ~mask & np.isfinite(raw).all(axis=-1)
    assert np.allclose(written.points.positions[kept], raw[kept], atol=1e-4)
    missing = ~mask & ~np.isfinite(raw).all(axis=-1)
    assert np.all(written.residuals[missing] < 0)

    summary = qa_summary(result)
    assert summary["marker_gaps"] == len(filled) + len(left)
    assert summary["gaps_filled"] == len(filled)
    assert summary["filled_share"] > 0
    assert summary["missing_share"] == pytest.approx(
        take.missing_fraction - summary["filled_share"], abs=1e-5
    )
    assert summary["score"] < 100


def test_a_swap_is_repaired_before_the_fill(clean: KeypointSequence) -> None:
    """A gap inside a swapped interval belongs to the other label: repaired first, the fill
    fills the right marker from its own trajectory."""
    a, b = clean.names.index("Derrick:LKNE"), clean.names.index("Derrick:LTHI")
    positions = clean.positions.copy()
    positions[500:541, [a, b]] = positions[500:541, [b, a]]
    positions[520:530, a] = np.nan  # LTHI's samples, under LKNE's label
    swapped = dataclasses.replace(clean, positions=positions)
    outcome = run_markers(swapped)
    swaps = [f for f in outcome.findings if f["kind"] == "swap"]
    assert len(swaps) == 1
    assert set(swaps[0]["markers"]) == {"Derrick:LKNE", "Derrick:LTHI"}
    assert (swaps[0]["start_frame"], swaps[0]["end_frame"]) == (500, 540)
    assert swaps[0]["applied"]
    assert swaps[0]["confidence"] >= 0.8
    gaps = [f for f in outcome.findings if f["kind"] in ("gap", "gap not filled")]
    assert [(g["joint"], g["start_frame"], g["end_frame"]) for g in gaps] == [
        ("Derrick:LTHI", 520, 529)
    ]
    assert outcome.markers is not None
    corrected = outcome.markers.positions
    assert np.array_equal(corrected[500:520, [a, b]], clean.positions[500:520, [a, b]])
    assert gaps[0]["kind"] == "gap"
    error = np.linalg.norm(corrected[520:530, b] - clean.positions[520:530, b], axis=-1)
    assert error.max() < 0.01  # metres
    summary_fields = qa_summary(analyze(swapped, AnalysisOptions(checks=("markers",))))
    assert summary_fields["marker_swaps"] == summary_fields["swaps_repaired"] == 1


def test_takes_without_markers_say_why_the_step_was_skipped(clean: KeypointSequence) -> None:
    video = dataclasses.replace(clean, source_format="openpose")
    result = analyze(video, AnalysisOptions(checks=("markers",)))
    assert result.report["steps"]["markers"]["state"] == "skipped"
    assert "not markers" in result.report["steps"]["markers"]["message"]
    assert result.markers is None
    summary = qa_summary(result)
    assert all(summary[k] is None for k in MARKER_FIELDS)
