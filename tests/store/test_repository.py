"""The repository on SQLite and on a real PostgreSQL (``-m postgres``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from mocapqa import __version__
from mocapqa.errors import ConflictError, InputError, NotFoundError
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository


def take_values(name: str) -> dict[str, Any]:
    return {
        "name": name,
        "format": "bvh",
        "kind": "motion",
        "size_bytes": 10,
        "sha256": "ab" * 32,
        "n_frames": 5,
        "fps": 30.0,
        "n_joints": 2,
        "file_name": name,
    }


def test_a_take_and_its_first_run_are_stored_together(repository: Repository) -> None:
    take_id, run_id = repository.add_take(take_values("a.bvh"), {"checks": ["twist"]})
    take = repository.get_take(take_id)
    run = repository.get_run(run_id)
    assert take["latest_run_id"] == run_id
    assert take["status"] == "queued"
    assert take["review_status"] == "unreviewed"
    assert run["input_sha256"] == "ab" * 32
    # the run records the limits model it uses: the default one, for a take outside a shoot
    assert run["options"] == {"checks": ["twist"], "limits_model": "default"}
    assert run["version"] == __version__


def test_run_lifecycle_records_progress_and_result(repository: Repository) -> None:
    take_id, run_id = repository.add_take(take_values("a.bvh"), {})
    with pytest.raises(ConflictError, match=r"Expected run \w+ to be done, got 'queued'"):
        repository.require_done(run_id)
    repository.mark_running(run_id)
    repository.set_progress(run_id, 140, "step")
    assert repository.get_run(run_id)["progress"] == 100
    repository.finish_run(run_id, {"n_findings": 3}, None, 0.5)
    done = repository.require_done(run_id)
    assert done["summary"] == {"n_findings": 3}
    assert repository.get_take(take_id)["status"] == "done"
    second = repository.add_run(take_id, {"checks": ["limits"]})
    repository.finish_run(second, None, "broken", 0.1)
    runs = repository.list_runs(take_id)
    assert [r["id"] for r in runs] == [run_id, second]
    assert repository.get_take(take_id)["status"] == "failed"


def test_listing_pages_and_filters_by_run_and_review_status(repository: Repository) -> None:
    ids = [repository.add_take(take_values(f"t{i}.bvh"), {}) for i in range(5)]
    repository.finish_run(ids[0][1], {}, None, 0.1)
    repository.add_review(ids[1][0], "approved", "fine", "ann")
    items, total = repository.list_takes(limit=2, offset=0)
    assert total == 5
    assert len(items) == 2
    items, total = repository.list_takes(status="done")
    assert total == 1
    assert items[0]["id"] == ids[0][0]
    items, total = repository.list_takes(review_status="approved")
    assert [i["id"] for i in items] == [ids[1][0]]
    _, total = repository.list_takes(review_status="unreviewed")
    assert total == 4
    with pytest.raises(InputError, match="Expected status in"):
        repository.list_takes(status="finished")


def test_reviews_are_kept_as_history(repository: Repository) -> None:
    take_id, _ = repository.add_take(take_values("a.bvh"), {})
    repository.add_review(take_id, "needs_fix", "left arm flips", "ann")
    repository.add_review(take_id, "approved", "", "bob")
    history = repository.list_reviews(take_id)
    assert [(r["status"], r["reviewer"]) for r in history] == [
        ("approved", "bob"),
        ("needs_fix", "ann"),
    ]
    assert history[0]["created_at"].tzinfo is not None
    assert repository.get_take(take_id)["review_status"] == "approved"
    with pytest.raises(InputError, match="Expected review status in"):
        repository.add_review(take_id, "great", "", "ann")


def test_interrupted_runs_are_requeued(repository: Repository) -> None:
    _, running = repository.add_take(take_values("a.bvh"), {})
    _, finished = repository.add_take(take_values("b.bvh"), {})
    repository.mark_running(running)
    repository.finish_run(finished, {}, None, 0.1)
    assert repository.recover_interrupted() == [running]
    run = repository.get_run(running)
    assert (run["status"], run["progress"]) == ("queued", 0)
    assert repository.get_run(finished)["status"] == "done"


def test_delete_removes_runs_and_reviews(repository: Repository) -> None:
    take_id, run_id = repository.add_take(take_values("a.bvh"), {})
    repository.add_review(take_id, "rejected", "", "ann")
    assert repository.delete_take(take_id) == [run_id]
    with pytest.raises(NotFoundError, match="Expected take"):
        repository.get_take(take_id)
    with pytest.raises(NotFoundError, match="Expected run"):
        repository.get_run(run_id)
    with pytest.raises(NotFoundError, match="Expected take"):
        repository.delete_take(take_id)


def test_files_are_written_whole_and_ids_are_checked(tmp_path: Path) -> None:
    files = FileStore(tmp_path)
    target = files.run_dir("0" * 32) / "report.json"
    files.write_bytes(target, b"{}")
    files.write_bytes(target, b'{"a": 1}')
    assert target.read_bytes() == b'{"a": 1}'
    assert [p.name for p in target.parent.iterdir()] == ["report.json"]
    with pytest.raises(NotFoundError, match="Expected a 32-character hex id"):
        files.run_dir("../../etc")


def test_a_take_of_a_shoot_deleted_meanwhile_is_not_found_not_a_database_error(
    repository: Repository,
) -> None:
    # An import whose shoot is deleted under it: the take's insert fails its foreign key.
    with pytest.raises(NotFoundError, match="Expected shoot 'gone' to exist"):
        repository.add_take({**take_values("late.bvh"), "shoot_id": "gone"}, {})
    assert repository.list_takes()[1] == 0


@pytest.mark.parametrize("lock_sees_it", [False, True])
def test_a_run_or_review_of_a_take_deleted_meanwhile_is_not_found(
    repository: Repository, monkeypatch: pytest.MonkeyPatch, lock_sees_it: bool
) -> None:
    # Another user deletes the take between the request's read of it and its write: the write
    # finds the take gone when it locks it, or (the lock read racing the delete) the insert
    # fails its foreign key; either way "not found", never a database error.
    take_id, _ = repository.add_take(take_values("a.bvh"), {})
    stale = repository.get_take(take_id)
    repository.delete_take(take_id)
    monkeypatch.setattr(repository, "get_take", lambda _: stale)
    if lock_sees_it:
        monkeypatch.setattr("mocapqa.store.repository.lock_take", lambda conn, take: stale)
    with pytest.raises(NotFoundError, match="deleted meanwhile"):
        repository.add_run(take_id, {})
    with pytest.raises(NotFoundError, match="deleted meanwhile"):
        repository.add_review(take_id, "approved", "", "ann")
    assert repository.list_takes()[1] == 0
