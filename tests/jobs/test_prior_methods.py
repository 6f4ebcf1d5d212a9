"""A shoot's reviewer prior learns from decisions on robust runs only: a run of the paper's
twist method scores no calibrated probability, so its decisions are no labels."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from tests.store.conftest import database_params, database_url

from mocapqa.jobs.run_folder import RunFolder
from mocapqa.jobs.shoot_prior import shoot_prior
from mocapqa.jobs.stored_run import load_report
from mocapqa.jobs.take_task import analyse_stored
from mocapqa.jobs.twist_items import twist_items_of
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.decisions import IntervalDecisions
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository
from mocapqa.store.shoots import ShootStore

KNEES = "bvh/cmu/iclone/005_05.bvh"


@pytest.fixture(params=database_params())
def repository(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Repository]:
    """A repository on an empty database."""
    repo = Repository(database_url(str(request.param), tmp_path))
    yield repo
    repo.close()


def take_values(name: str, shoot_id: str) -> dict[str, Any]:
    return {
        "name": name, "format": "bvh", "kind": "motion", "size_bytes": 10,
        "sha256": name.encode().hex().ljust(64, "0")[:64], "n_frames": 5, "fps": 30.0,
        "n_joints": 2, "file_name": name, "shoot_id": shoot_id,
    }  # fmt: skip


class Shoot:
    """A shoot in a store whose runs are 005_05 analysed for the twist check by one method."""

    def __init__(self, repository: Repository, files: FileStore, corpus_dir: Path) -> None:
        self.repository, self.files = repository, files
        self.path = corpus_dir / KNEES
        self.id = ShootStore(repository.engine).create("methods")["id"]
        self.decisions = IntervalDecisions(repository.engine)

    def take(self, name: str) -> str:
        """A new take of the shoot; its id."""
        take_id, _ = self.repository.add_take(take_values(name, self.id), {})
        return take_id

    def run(self, take_id: str, method: str) -> str:
        """A finished twist run of ``method`` on the take, with its report; the run's id."""
        options = AnalysisOptions(checks=("twist",), twist_method=method).to_json()
        run_id = self.repository.add_run(take_id, options)
        analyse_stored(str(self.path), "bvh", "005_05", options, run_id, str(self.files.root))
        self.repository.finish_run(run_id, {"qa": {"rig": "character_creator"}}, None, 0.1)
        return run_id

    def accept_all(self, run_id: str) -> int:
        """Accept every twist interval of the run's report; how many."""
        findings = load_report(RunFolder.of(self.files, run_id).report)["findings"]
        ids = [int(f["id"]) for f in findings if f["kind"] == "twist"]
        for interval in ids:
            self.decisions.add(run_id, interval, "accept", "", "ana", "x")
        return len(ids)

    def prior_of(self, take_id: str) -> Any:
        """The prior a new run of the take would use."""
        take = {"id": take_id, "shoot_id": self.id, "review_status": "unreviewed"}
        return shoot_prior(self.decisions, self.files, take)


def test_the_prior_counts_decisions_on_robust_runs_only(
    repository: Repository, corpus_dir: Path, tmp_path: Path
) -> None:
    shoot = Shoot(repository, FileStore(tmp_path / "data"), corpus_dir)
    decided_paper, decided_both, target = shoot.take("a.bvh"), shoot.take("b.bvh"), shoot.take("c")

    paper_run = shoot.run(decided_paper, "paper")
    assert shoot.accept_all(paper_run) > 0  # the paper's rule finds intervals on 005_05
    assert twist_items_of(shoot.files, paper_run) == {}  # its confidence is no probability
    assert shoot.decisions.shoot_labels(shoot.id) == []
    assert shoot.prior_of(target) is None

    # A take decided on a robust run, then re-run with the paper's method and decided again:
    # its robust run's labels stay its labels.
    robust_run = shoot.run(decided_both, "robust")
    accepted = shoot.accept_all(robust_run)
    assert accepted > 0
    assert twist_items_of(shoot.files, robust_run)
    newer_paper_run = shoot.run(decided_both, "paper")
    assert shoot.accept_all(newer_paper_run) > 0
    labels = shoot.decisions.shoot_labels(shoot.id)
    assert {label["run_id"] for label in labels} == {robust_run}
    assert len(labels) == accepted

    prior = shoot.prior_of(target)
    assert prior is not None
    assert prior.runs == (robust_run,)
    assert prior.summary()["accepted"] == accepted
