"""The demo takes: bundled files (with attribution in ``mocapqa/data/demo/README.md``) loaded
into an empty database and analysed before the server starts answering."""

from __future__ import annotations

import logging
from importlib import resources
from pathlib import Path

from mocapqa.jobs.intake import ingest_take
from mocapqa.jobs.runner import JobRunner
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository

__all__ = ["DEMO_FILES", "demo_paths", "load_demo"]

DEMO_FILES = ("cmu_12_01_walk_twist_errors.bvh", "pose2sim_S00_P00_T01_BalancingTrial.trc")
"""File names of the demo takes in ``mocapqa/data/demo``, in loading order."""
log = logging.getLogger(__name__)


def demo_paths() -> list[Path]:
    """The bundled demo files that exist, in :data:`DEMO_FILES` order."""
    folder = resources.files("mocapqa") / "data" / "demo"
    paths = [Path(str(folder / name)) for name in DEMO_FILES]
    return [p for p in paths if p.is_file()]


def load_demo(
    repository: Repository, files: FileStore, runner: JobRunner, timeout_s: float = 120.0
) -> list[str]:
    """Load and analyse the demo takes when there are no takes yet; returns the new take ids."""
    _, total = repository.list_takes(limit=1)
    if total:
        return []
    take_ids = []
    for path in demo_paths():
        with path.open("rb") as handle:
            take_id, run_id = ingest_take(handle, path.name, repository, files, runner, 1 << 30)
        runner.wait(run_id, timeout_s)
        take_ids.append(take_id)
        log.info("demo take %s loaded", path.name)
    return take_ids
