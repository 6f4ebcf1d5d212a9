"""A user's place in the run queue is taken under the runner's lock, not checked and then used.

Before, a route checked the user's queued runs and submitted its run later: 36 simultaneous run
requests against a quota of 20 got 25 accepted. Here 36 threads ask at once, each holding the
place a moment before submitting (as a route records its run in between).
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

from mocapqa.api.deps import Services, run_places
from mocapqa.config import Settings
from mocapqa.errors import RateLimitError
from mocapqa.jobs.runner import JobRunner
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository

QUOTA = 20
ASKING = 36


def test_parallel_requests_get_exactly_the_quota(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, max_queued_runs_per_user=QUOTA)
    repository = Repository(settings.resolved_database_url)
    files = FileStore(tmp_path)
    runner = JobRunner(repository, files, workers=1)  # never started: runs stay queued
    services = Services(settings, repository, files, runner)
    start = threading.Barrier(ASKING)
    outcomes: list[str] = []

    def ask(index: int) -> None:
        start.wait()
        try:
            with run_places(services, "user:1"):
                time.sleep(0.01)  # the route records the run meanwhile
                runner.submit(f"run-{index}", client="user:1")
            outcomes.append("accepted")
        except RateLimitError:
            outcomes.append("refused")

    threads = [threading.Thread(target=ask, args=(i,)) for i in range(ASKING)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    repository.close()

    assert outcomes.count("accepted") == QUOTA
    assert outcomes.count("refused") == ASKING - QUOTA
    assert runner.pending("user:1") == QUOTA  # no place left held


def test_a_block_that_fails_gives_its_places_back(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, max_queued_runs_per_user=2)
    repository = Repository(settings.resolved_database_url)
    runner = JobRunner(repository, FileStore(tmp_path), workers=1)
    services = Services(settings, repository, FileStore(tmp_path), runner)
    granted: list[int] = []

    def record_fails() -> None:
        with run_places(services, "user:2", wanted=5) as places:
            granted.append(places)
            raise RuntimeError("the run could not be recorded")

    with pytest.raises(RuntimeError, match="could not be recorded"):
        record_fails()
    assert granted == [2]
    assert runner.pending("user:2") == 0
    repository.close()
