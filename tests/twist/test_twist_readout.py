"""Each twist finding says what the default does with it and which evidence decided."""

from __future__ import annotations

from pathlib import Path

from mocapqa.io.bvh import read_bvh
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.twist.choice import decision_readout


def test_the_findings_of_real_flips_say_why_they_are_applied_or_listed(corpus_dir: Path) -> None:
    motion = read_bvh(corpus_dir / "bvh" / "cmu" / "iclone" / "005_05.bvh")
    report = analyze(motion, AnalysisOptions(checks=("twist",))).report
    twist = [f for f in report["findings"] if f["kind"] == "twist"]
    assert twist
    for finding in twist:
        verdict = "the default applies it" if finding["applied"] else "the default only reports it"
        assert finding["readout"].startswith(verdict), finding
    by_anatomy = [f for f in twist if "outside the natural range" in f["readout"]]
    assert by_anatomy, [f["readout"] for f in twist]
    assert all(f["applied"] for f in by_anatomy)


def test_a_reason_recorded_with_the_evidence_is_the_readout() -> None:
    evidence: dict[str, float | str] = {
        "calibrated": 1.0, "rule": "natural_roll", "default": "listed",
        "reason": "smaller than this rig's natural upper arm roll (p99 16.5°)",
    }  # fmt: skip
    assert decision_readout(evidence) == (
        "the default only reports it: smaller than this rig's natural upper arm roll (p99 16.5°)"
    )
    assert decision_readout({}) == ""
