"""A shoot's labels: the newest decision of each interval of each take's decided run."""

from __future__ import annotations

from typing import Any

from mocapqa.store.decisions import IntervalDecisions
from mocapqa.store.repository import Repository
from mocapqa.store.shoots import ShootStore


def take_values(name: str, shoot_id: str | None) -> dict[str, Any]:
    return {
        "name": name, "format": "bvh", "kind": "motion", "size_bytes": 10,
        "sha256": name.encode().hex().ljust(64, "0")[:64], "n_frames": 5, "fps": 30.0,
        "n_joints": 2, "file_name": name, "shoot_id": shoot_id,
    }  # fmt: skip


def test_the_labels_of_a_shoot_are_its_takes_newest_decisions(repository: Repository) -> None:
    shoots = ShootStore(repository.engine)
    shoot = shoots.create("day 1")["id"]
    other_shoot = shoots.create("day 2")["id"]
    first, first_run = repository.add_take(take_values("a.bvh", shoot), {})
    second, second_run = repository.add_take(take_values("b.bvh", shoot), {})
    _, elsewhere_run = repository.add_take(take_values("c.bvh", other_shoot), {})
    for run_id in (first_run, second_run, elsewhere_run):
        repository.finish_run(run_id, {"qa": {"rig": "cmu"}}, None, 0.1)
    decisions = IntervalDecisions(repository.engine)
    assert decisions.shoot_labels(shoot) == []

    decisions.add(first_run, 0, "reject", "", "ana", "x")
    decisions.add(first_run, 0, "accept", "", "ana", "x")  # the newest counts
    decisions.add(first_run, 2, "reject", "", "ana", "x")
    decisions.add(second_run, 1, "accept", "", "bo", "x")
    decisions.add(elsewhere_run, 0, "accept", "", "bo", "x")
    repository.add_review(second, "approved", "", "bo")

    labels = decisions.shoot_labels(shoot)
    assert [(r["take_id"], r["interval_id"], r["decision"]) for r in labels] == sorted(
        [(first, 0, "accept"), (first, 2, "reject"), (second, 1, "accept")]
    )
    by_take = {r["take_id"]: r for r in labels}
    assert by_take[first]["review_status"] == "unreviewed"
    assert by_take[second]["review_status"] == "approved"
    assert by_take[first]["run_id"] == first_run
    assert by_take[first]["rig"] == "cmu"

    # A newer run of the first take with its own decision: that run's labels replace the old.
    rerun = repository.add_run(first, {})
    repository.finish_run(rerun, {"qa": {"rig": "cmu"}}, None, 0.1)
    decisions.add(rerun, 5, "reject", "", "ana", "x")
    labels = decisions.shoot_labels(shoot)
    assert [(r["run_id"], r["interval_id"]) for r in labels if r["take_id"] == first] == [
        (rerun, 5)
    ]
