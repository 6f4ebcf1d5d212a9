"""A run whose take is deleted while it writes its outputs is cancelled, not failed."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import pytest

from mocapqa.errors import ParseError
from mocapqa.jobs.intake import ingest_take
from mocapqa.jobs.runner import JobRunner
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository

WALK = Path("bvh") / "cmu" / "cmu_12_01_walk.bvh"


@pytest.mark.parametrize("error", [FileNotFoundError("report.json.tmp"), ParseError("gone")])
def test_a_run_broken_by_its_take_being_deleted_is_cancelled_not_failed(
    corpus_dir: Path, tmp_path: Path, caplog: pytest.LogCaptureFixture, error: Exception
) -> None:
    files = FileStore(tmp_path / "data")
    repository = Repository(f"sqlite:///{tmp_path / 'db.sqlite3'}")
    runner = JobRunner(repository, files, workers=1)

    def deleted_while_writing(run_id: str, *args: Any, **kwargs: Any) -> dict[str, Any]:
        # The take is deleted between two progress reports; writing the next file then fails.
        runner.cancel([run_id])
        raise error

    runner._execute_here = deleted_while_writing  # type: ignore[method-assign]
    caplog.set_level(logging.INFO, logger="mocapqa")
    runner.start()
    with (corpus_dir / WALK).open("rb") as handle:
        _, run_id = ingest_take(handle, "walk.bvh", repository, files, runner, 1 << 30)
    runner.wait(run_id)
    runner.shutdown()
    run = repository.get_run(run_id)
    repository.close()
    assert run["status"] != "failed", run
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR], caplog.text
    assert f"run {run_id} cancelled" in caplog.text
    assert not files.run_dir(run_id).exists()
