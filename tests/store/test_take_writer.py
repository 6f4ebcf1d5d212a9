"""The one writer of a take and its run, on SQLite and PostgreSQL: an upload's take (queued run)
and a batch's take (done run) get the same rows as the store would rebuild for them, the limits
model a new run checks with is chosen in one place, and every listing hands out UTC times."""

from __future__ import annotations

from datetime import UTC
from typing import Any

import pytest
from sqlalchemy import select

from mocapqa.errors import NotFoundError
from mocapqa.limits.catalog import DEFAULT_MODEL
from mocapqa.store.limits_runs import run_limits_model
from mocapqa.store.qa import sync_take
from mocapqa.store.repository import Repository
from mocapqa.store.shoots import ShootStore
from mocapqa.store.stamps import new_id
from mocapqa.store.tables import take_qa
from mocapqa.store.take_writer import DoneTake

SUMMARY = {
    "n_findings": 2,
    "qa": {
        "score": 71.5,
        "rig": "cmu",
        "violation_share": 0.1,
        "joint_violations": {"knee": 0.1},
        "foot_skates": 2,
        "foot_worst_skate": 3.25,
        "foot_skate_unit": "cm",
        "foot_penetrations": 1,
        "foot_floating": 0,
    },
}


def take_values(name: str, shoot_id: str | None = None) -> dict[str, Any]:
    return {
        "name": name,
        "format": "bvh",
        "kind": "motion",
        "size_bytes": 10,
        "sha256": new_id() * 2,
        "n_frames": 60,
        "fps": 30.0,
        "n_joints": 2,
        "file_name": name,
        "shoot_id": shoot_id,
    }


def qa_row(repository: Repository, take_id: str) -> dict[str, Any]:
    with repository.engine.connect() as conn:
        row = conn.execute(select(take_qa).where(take_qa.c.take_id == take_id)).mappings().one()
    return dict(row)


def rebuilt_qa_row(repository: Repository, take_id: str) -> dict[str, Any]:
    """The row the store rebuilds from the stored take, its latest run and review."""
    with repository.engine.begin() as conn:
        sync_take(conn, take_id)
    return qa_row(repository, take_id)


def test_a_new_take_s_summary_row_is_the_one_the_store_would_rebuild(
    repository: Repository,
) -> None:
    shoots = ShootStore(repository.engine)
    shoot_id = str(shoots.create("writer")["id"])
    queued, _ = repository.add_take(take_values("queued.bvh", shoot_id), {})
    done = {**take_values("done.bvh", shoot_id), "id": new_id()}
    shoots.record_done([DoneTake(done, new_id(), {"limits_model": "default"}, SUMMARY, 0.2)])
    for take_id in (queued, str(done["id"])):
        written = qa_row(repository, take_id)
        assert written == rebuilt_qa_row(repository, take_id)
    assert qa_row(repository, queued)["status"] == "queued"
    assert qa_row(repository, queued)["duration_s"] == 2.0
    row = qa_row(repository, str(done["id"]))
    assert (row["status"], row["score"], row["n_findings"]) == ("done", 71.5, 2)
    assert row["joint_violations"] == {"knee": 0.1}
    feet = ("foot_skates", "foot_worst_skate", "foot_skate_unit", "foot_penetrations")
    assert tuple(row[k] for k in feet) == (2, 3.25, "cm", 1)
    assert row["foot_floating"] == 0
    assert qa_row(repository, queued)["foot_skates"] is None  # not analysed yet: no figure


def test_a_new_run_checks_limits_with_the_named_then_the_shoot_s_then_the_default_model(
    repository: Repository,
) -> None:
    shoots = ShootStore(repository.engine)
    shoot_id = str(shoots.create("limits")["id"])
    shoots.set_limits_model(shoot_id, "tight")
    assert shoots.run_limits_model("mine", shoot_id) == "mine"
    assert shoots.run_limits_model(None, shoot_id) == "tight"
    assert shoots.run_limits_model(None, None) == DEFAULT_MODEL
    with pytest.raises(NotFoundError, match="Expected shoot 'gone' to exist"):
        shoots.run_limits_model(None, "gone")
    with repository.engine.connect() as conn:
        assert run_limits_model(conn, None, shoot_id) == "tight"

    in_shoot, first = repository.add_take(take_values("a.bvh", shoot_id), {})
    _, alone = repository.add_take(take_values("b.bvh"), {})
    named = repository.add_run(in_shoot, {"limits_model": "loose"})
    again = repository.add_run(in_shoot, {})
    chosen = {run: repository.get_run(run)["options"]["limits_model"] for run in
              (first, alone, named, again)}  # fmt: skip
    assert chosen == {first: "tight", alone: DEFAULT_MODEL, named: "loose", again: "tight"}


def test_every_listing_hands_out_utc_times(repository: Repository) -> None:
    shoots = ShootStore(repository.engine)
    shoot_id = str(shoots.create("times")["id"])
    take_id, run_id = repository.add_take(take_values("a.bvh", shoot_id), {})
    repository.finish_run(run_id, SUMMARY, None, 0.1)
    done = {**take_values("b.bvh", shoot_id), "id": new_id()}
    shoots.record_done([DoneTake(done, new_id(), {}, SUMMARY, 0.2)])
    rows = [
        repository.get_take(take_id),
        *repository.list_takes()[0],
        repository.get_run(run_id),
        *repository.list_runs(take_id),
        *shoots.page(shoot_id)[0],
        *shoots.qa_rows([take_id, str(done["id"])]).values(),
        shoots.get(shoot_id),
    ]
    following, _ = shoots.next_for_review(shoot_id)
    assert following is not None
    rows.append(following)
    for row in rows:
        assert row["created_at"].tzinfo is not None
        assert row["created_at"].utcoffset() == UTC.utcoffset(None)
