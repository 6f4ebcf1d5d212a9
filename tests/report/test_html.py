"""The HTML report from real pipeline runs: self-contained, complete, honest about gaps."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from mocapqa.io.formats import read_take
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.report.findings import limit_findings, normalise_findings, twist_findings
from mocapqa.report.html import build_report, report_from_analysis

# A take with twist intervals, limb spins and joint-limit violations (its real knee errors).
TAKE = "bvh/cmu/iclone/005_05.bvh"
MEDIAPIPE = "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv"
TINY_PNG = (
    b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x01\x00\x00\x00\x01\x08\x02\x00\x00"
    b"\x00\x90wS\xde\x00\x00\x00\x0cIDATx\x9cc\xf8\xff\xff?\x00\x05\xfe\x02\xfe\xa7\x35\x81"
    b"\x84\x00\x00\x00\x00IEND\xaeB`\x82"
)


@pytest.fixture(scope="module")
def knees_analysis(corpus_dir: Path) -> dict[str, Any]:
    return analyze(read_take(corpus_dir / TAKE), AnalysisOptions()).report


def _external_references(page: str) -> list[str]:
    # Plotly's own source mentions map-tile URLs in strings; only markup can load anything.
    markup = re.sub(r"<script[^>]*>.*?</script>", "", page, flags=re.DOTALL)
    return re.findall(r"""(?:src|href)\s*=\s*["'](?!data:|#)([^"']+)""", markup)


def test_report_is_self_contained(knees_analysis: dict[str, Any]) -> None:
    page = report_from_analysis(knees_analysis, {"name": "knees"}, contact_sheet_png=TINY_PNG)
    assert page.startswith("<!DOCTYPE html>")
    assert _external_references(page) == []
    assert "Content-Security-Policy" in page
    assert "<script src" not in page
    assert "Plotly" in page
    assert len(page) > 1_000_000
    assert "data:image/png;base64," in page


def test_report_lists_every_finding_and_both_timelines(knees_analysis: dict[str, Any]) -> None:
    page = report_from_analysis(knees_analysis, {"name": "knees"})
    findings = knees_analysis["findings"]
    assert {f["kind"] for f in findings} >= {"twist", "spin", "limits", "skate"}
    table = page.split('id="findings"', 1)[1].split("</table>", 1)[0]
    assert table.count("<tr>") == len(findings) + 1  # header row
    assert 'id="twist-timeline"' in page
    assert 'id="limits-timeline"' in page
    assert "no filter chosen for motion takes" in page  # the filter section says why not
    assert "twist_method" in page
    assert "mocapqa" in page


def test_keypoint_report_explains_missing_rotation_checks(corpus_dir: Path) -> None:
    analysis = analyze(read_take(corpus_dir / MEDIAPIPE), AnalysisOptions()).report
    page = report_from_analysis(analysis, {"name": "landmarks"})
    assert "keypoint takes have no joint rotations" in page
    assert 'id="filter-weights"' in page


def test_build_report_without_analyses_marks_sections_unavailable() -> None:
    page = build_report(
        {"name": "x", "fps": 30}, unavailable={"twist": "twist analysis not installed"}
    )
    assert "twist analysis not installed" in page
    assert "The limits analysis was not run." in page
    assert "No flagged intervals." in page
    assert "No contact sheet" in page


def test_limit_runs_come_from_consecutive_invalid_frames() -> None:
    limits = {
        "joints": [
            {
                "name": "Knee",
                "frames": {
                    "frame": [0, 1, 2, 3, 4, 5],
                    "valid": [True, False, False, True, False, True],
                    "score_deg": [0, 3.0, 5.0, 0, 2.0, 0],
                },
            }
        ]
    }
    runs = limit_findings(limits)
    assert [(r["start_frame"], r["end_frame"], r["violation_deg"]) for r in runs] == [
        (1, 2, 5.0),
        (4, 4, 2.0),
    ]
    heat = {"joints": ["Knee"], "frames": [0, 2, 4], "score_deg": [[0.0, 4.0, 4.5]]}
    assert [(r["start_frame"], r["end_frame"]) for r in limit_findings(heat)] == [(2, 4)]


def test_findings_are_normalised_by_kind() -> None:
    given = [
        {"kind": "twist", "joint": "A", "start_frame": 3, "end_frame": 9, "value": -20.0},
        {"kind": "limits", "joint": "B", "start_frame": 1, "end_frame": 1, "value": 4.0},
    ]
    out = normalise_findings(given)
    assert out[0]["offset_deg"] == -20.0
    assert out[1]["kind"] == "limits"
    assert out[1]["violation_deg"] == 4.0
    twist = {"intervals": [{"joint": "A", "start_frame": 3, "end_frame": 9, "offset_deg": 12.5}]}
    assert twist_findings(twist)[0]["offset_deg"] == 12.5


def test_twist_findings_keep_whether_the_interval_was_applied() -> None:
    # The contact sheet draws a corrected pose only for applied intervals.
    twist = {
        "intervals": [
            {"joint": "A", "start_frame": 3, "end_frame": 9, "confidence": 0.14, "applied": False},
            {"joint": "A", "start_frame": 20, "end_frame": 22, "applied": True},
            {"joint": "B", "start_frame": 1, "end_frame": 2},
        ]
    }
    found = twist_findings(twist)
    assert [f.get("applied") for f in found] == [False, True, None]
