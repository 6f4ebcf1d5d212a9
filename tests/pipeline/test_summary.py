"""The QA summary and score on real takes, and the score's documented properties."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from mocapqa.jobs.demo import demo_paths
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.loading import read_take_file
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.pipeline.summary import SCORE_TERMS, SUMMARY_FIELDS, qa_score, qa_summary

defect = st.one_of(st.none(), st.floats(0, 1e6, allow_nan=False))


def test_no_defect_scores_100() -> None:
    assert qa_score({}) == 100.0
    assert qa_score(dict.fromkeys(SCORE_TERMS, 0.0)) == 100.0


@given(
    st.fixed_dictionaries({name: defect for name in SCORE_TERMS}),
    st.sampled_from(list(SCORE_TERMS)),
    st.floats(0, 1e6),
)
def test_score_is_monotone_in_each_defect(
    defects: dict[str, float | None], name: str, more: float
) -> None:
    base = qa_score(defects)
    worse = dict(defects)
    worse[name] = (defects[name] or 0.0) + more
    assert qa_score(worse) <= base
    floor = 100.0
    for weight, _ in SCORE_TERMS.values():
        floor *= 1 - weight
    assert floor - 0.1 <= qa_score(worse) <= 100.0


def test_each_defect_lowers_the_score() -> None:
    for name, (_, half) in SCORE_TERMS.items():
        assert qa_score({name: half}) < qa_score({name: half / 2}) < 100.0


def _summary(path: Path) -> dict[str, object]:
    return qa_summary(analyze(read_take_file(path, ""), AnalysisOptions()))


def test_summary_of_the_demo_walk_with_twist_errors() -> None:
    walk = next(p for p in demo_paths() if p.suffix == ".bvh")
    result = analyze(read_take_file(walk, ""), AnalysisOptions())
    summary = qa_summary(result)
    assert set(SUMMARY_FIELDS) <= set(summary)
    twist = [f for f in result.report["findings"] if f["kind"] == "twist"]
    assert summary["twist_intervals"] == len(twist) > 0
    assert summary["corrected_joint_frames"] == sum(
        f["end_frame"] - f["start_frame"] + 1 for f in twist
    )
    assert summary["rig"] == "cmu"
    assert summary["n_frames"] == result.report["summary"]["n_frames"] == 523  # T-pose dropped
    assert 0 < summary["violation_share"] <= 1
    assert summary["worst_joint"] in summary["joint_violations"]
    assert summary["filter_residual_mm"] is None
    assert summary["missing_share"] == 0.0
    assert 0 <= summary["score"] < 100
    assert summary["limb_spins"] == 0


def test_limb_spins_are_counted_and_do_not_change_the_score(corpus_dir: Path) -> None:
    take = corpus_dir / "bvh" / "cmu" / "iclone" / "005_03.bvh"
    result = analyze(read_take_file(take, ""), AnalysisOptions())
    summary = qa_summary(result)
    spins = [f for f in result.report["findings"] if f["kind"] == "spin"]
    assert summary["limb_spins"] == len(spins) == 3
    without = dict(result.report)
    without["findings"] = [f for f in result.report["findings"] if f["kind"] != "spin"]
    assert qa_summary(replace(result, report=without))["score"] == summary["score"]


def test_twist_fixes_cost_the_score(corpus_dir: Path) -> None:
    walk = next(p for p in demo_paths() if p.suffix == ".bvh")
    injected = _summary(walk)
    # The same rig without injected twist errors scores higher.
    clean = _summary(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    assert clean["twist_intervals"] < injected["twist_intervals"]
    assert clean["score"] > injected["score"]


@pytest.mark.parametrize(
    "relative",
    [
        "keypoints/pose2sim/S00_P00_T00_StaticTrial/pose-3d/S00_P00_T00_StaticTrial_0-12.trc",
        "keypoints/mediapipe/google_mediapipe_testdata/pose_landmarks.pbtxt",
    ],
)
def test_summary_of_keypoint_takes(corpus_dir: Path, relative: str) -> None:
    summary = _summary(corpus_dir / relative)
    assert summary["rig"] == "keypoints"
    assert summary["twist_intervals"] is None
    assert summary["limb_spins"] is None
    assert summary["violation_share"] is None
    assert 0 <= summary["missing_share"] <= 1
    assert 0 <= summary["score"] <= 100
