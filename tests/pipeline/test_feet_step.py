"""The run's feet step: the feet check's findings in the run's shape, its contacts in the
report, its counts in the QA summary and score, and a reason when a take has no feet."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.errors import InputError
from mocapqa.feet.pin import marker_foot_members
from mocapqa.io.formats import read_take
from mocapqa.pipeline.analyze import AnalysisResult, analyze
from mocapqa.pipeline.feet import check_take_feet, feet_report_json
from mocapqa.pipeline.feet_step import FEET_FINDING_KINDS, feet_findings
from mocapqa.pipeline.options import AnalysisOptions, describe_options, take_checks
from mocapqa.pipeline.summary import FEET_FIELDS, qa_summary

SKATING = Path("bvh/cmu/iclone/007_04.bvh")  # a real 1.4-cm slide: skate findings
TENNIS = Path("c3d/optitrack/kinematics_tennis_serve.c3d")  # skate findings on marker feet
NO_FEET = Path("c3d/btk/MotionMonitorC3D.c3d")  # markers M1–M7, no foot markers
SHARED = ("kind", "joint", "start_frame", "end_frame", "value", "unit", "confidence")


@pytest.fixture(scope="module")
def skating(corpus_dir: Path) -> AnalysisResult:
    return analyze(read_take(corpus_dir / SKATING), AnalysisOptions(checks=("feet",)))


def test_every_kind_of_take_runs_the_feet_check_and_the_form_offers_it() -> None:
    assert "feet" in AnalysisOptions().checks
    assert "feet" in take_checks("motion")
    assert "feet" in take_checks("keypoints", "c3d")
    assert "feet" in take_checks("keypoints", "openpose")
    described = describe_options()
    assert "feet" in [g["check"] for g in described["groups"]]
    assert described["presets"]["feet only"] == {**described["presets"]["full check"],
                                                 "checks": ["feet"]}  # fmt: skip


def test_a_skating_bvh_lists_its_skate_on_the_foot_with_contacts_in_the_report(
    corpus_dir: Path, skating: AnalysisResult
) -> None:
    report = skating.report
    assert report["steps"]["feet"]["state"] == "done"
    feet = [f for f in report["findings"] if f["kind"] in FEET_FINDING_KINDS]
    assert [f["kind"] for f in feet] == ["skate"]
    (skate,) = feet
    assert set(SHARED) <= set(skate)
    # The same finding and contacts as `mocapqa feet check --json` (the fixed contract).
    points, check, skipped = check_take_feet(read_take(corpus_dir / SKATING))
    expected = feet_report_json(points, check, skipped)
    (item,) = expected["findings"]
    assert (skate["foot"], skate["start_frame"], skate["end_frame"]) == (
        item["foot"], item["start"], item["end"],
    )  # fmt: skip
    assert skate["joint"] == report["summary"]["roles"][f"{skate['foot']}_foot"]
    # A BVH stores no unit: the size is a share of the estimated body height.
    assert skate["unit"] == "% height"
    assert skate["value"] == pytest.approx(100 * item["size_rel_height"], abs=1e-3)
    assert skate["id"] == f"skate-{skate['foot']}-{skate['start_frame']}"
    assert 0 < skate["confidence"] <= 1
    contacts = report["series"]["feet"]["contacts"]
    assert [(c["foot"], c["start"], c["end"]) for c in contacts] == [
        (c["foot"], c["start"], c["end"]) for c in expected["contacts"]
    ]
    assert report["summary"]["findings_by_kind"]["skate"] == 1


def test_the_summary_counts_the_feet_findings_and_the_score_pays_for_them(
    skating: AnalysisResult,
) -> None:
    summary = qa_summary(skating)
    assert summary["foot_skates"] == 1
    assert summary["foot_contacts"] == len(skating.report["series"]["feet"]["contacts"]) > 0
    assert summary["foot_penetrations"] == summary["foot_floating"] == summary["foot_jitter"] == 0
    assert summary["score"] is not None
    assert summary["score"] < 100


def test_sizes_in_a_metric_unit_are_centimetres() -> None:
    check = {"findings": [{
        "kind": "penetration", "foot": "right", "start": 10, "end": 19, "peak": 14, "size": 0.031,
        "size_cm": 3.1, "size_rel_height": 0.018, "id": "penetration-right-10",
    }]}  # fmt: skip
    (finding,) = feet_findings(check, {"left": "LHeel", "right": "RHeel"})
    assert (finding["joint"], finding["value"], finding["unit"]) == ("RHeel", 3.1, "cm")
    assert finding["confidence"] is None
    assert finding["readout"] == "right foot, foot below the floor 3.1 cm"


def test_a_take_without_feet_skips_the_step_with_the_reason(corpus_dir: Path) -> None:
    result = analyze(read_take(corpus_dir / NO_FEET), AnalysisOptions(checks=("feet",)))
    step = result.report["steps"]["feet"]
    assert step["state"] == "skipped"
    assert step["message"].startswith("no feet to check")
    assert result.report["series"].get("feet") is None
    summary = qa_summary(result)
    assert all(summary[k] is None for k in FEET_FIELDS)


def test_a_run_that_locks_feet_pins_only_the_foot_markers_of_its_skates(corpus_dir: Path) -> None:
    take = read_take(corpus_dir / TENNIS)
    plain = analyze(take, AnalysisOptions(checks=("feet",)))
    locked = analyze(take, AnalysisOptions(checks=("feet",), feet_apply="skates"))
    skates = [f for f in locked.report["findings"] if f["kind"] == "skate"]
    assert skates
    assert all(f["applied"] is True for f in skates)
    assert all(f["applied"] is False for f in plain.report["findings"] if f["kind"] == "skate")
    # Only the foot markers move (the heel, toe, ankle and foot-cluster ones of each side).
    points, _, _ = check_take_feet(take)
    _, members = marker_foot_members(take.names, points)
    feet = sorted({m for side in members for m in side})
    moved = np.flatnonzero(
        np.nanmax(np.abs(locked.corrected_points - plain.corrected_points), axis=(0, 2)) > 0
    )
    assert moved.size
    assert set(moved.tolist()) <= set(feet)
    # The corrected C3D is written from the marker repair: its feet are pinned alike.
    repaired = analyze(take, AnalysisOptions(checks=("markers", "feet")))
    pinned = analyze(take, AnalysisOptions(checks=("markers", "feet"), feet_apply="skates"))
    assert repaired.markers is not None
    assert pinned.markers is not None
    changed = np.flatnonzero(
        np.nanmax(np.abs(pinned.markers.positions - repaired.markers.positions), axis=(0, 2)) > 0
    )
    assert changed.size
    assert set(changed.tolist()) <= set(feet)
    np.testing.assert_array_equal(pinned.markers.residuals, repaired.markers.residuals)
    # Nothing is locked for a choice that names no skate of the take's: the run fails, naming it.
    with pytest.raises(InputError, match=r"feet_apply ids of skate findings.*skate-left-99999"):
        analyze(take, AnalysisOptions(checks=("feet",), feet_apply="skate-left-99999"))
