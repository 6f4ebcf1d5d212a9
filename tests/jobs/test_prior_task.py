"""A worker's run (the Dask path) uses and records the reviewer prior the server sends."""

from __future__ import annotations

import json
from pathlib import Path

from mocapqa.jobs.run_folder import RunFolder
from mocapqa.jobs.stored_run import load_report
from mocapqa.jobs.take_task import analyse_stored
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.files import FileStore
from mocapqa.twist.reviewer_prior import ReviewerPrior

KNEES = "bvh/cmu/iclone/005_05.bvh"


def test_a_worker_run_records_the_prior_it_was_sent(corpus_dir: Path, tmp_path: Path) -> None:
    path = corpus_dir / KNEES
    options = AnalysisOptions(checks=("twist",)).to_json()
    prior = ReviewerPrior.from_decisions(
        "shoot", [("character_creator", "CC_Base_R_Calf", 0.1, "accept")] * 12, ["run-a"]
    )
    files = FileStore(tmp_path / "data")
    analyse_stored(str(path), "bvh", "005_05", options, "a" * 32, str(files.root))
    analyse_stored(
        str(path), "bvh", "005_05", options, "b" * 32, str(files.root), None, prior.to_json()
    )
    first, second = (RunFolder.of(files, r) for r in ("a" * 32, "b" * 32))
    assert not first.prior.exists()  # the first call had no prior
    recorded = json.loads(second.prior.read_text(encoding="utf-8"))
    assert ReviewerPrior.from_json(recorded) == prior
    report = load_report(second.report)
    assert report["reviewer_prior"]["hash"] == prior.content_hash
    assert "reviewer_prior" not in load_report(first.report)
    readouts = [f["readout"] for f in report["findings"] if f["kind"] == "twist"]
    assert any("by 12 accepted intervals on this joint in this shoot" in r for r in readouts)
