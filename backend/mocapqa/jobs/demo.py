"""The demo takes: bundled files (with attribution in ``mocapqa/data/demo/README.md``) loaded
into an empty database and analysed before the server starts answering.

Beside the single demo takes, a "Demo shoot" holds copies of them plus a few real takes of the
project's corpus when it is found (``MOCAPQA_CORPUS_DIR`` or ``shared/data`` beside the
checkout: the CMU walk, PyMO's walk and Pose2Sim TRCs, whose licences allow it); without the
corpus the shoot holds the two demo takes only.
"""

from __future__ import annotations

import logging
from importlib import resources
from pathlib import Path

from mocapqa.corpus import find_corpus
from mocapqa.jobs.intake import ingest_take
from mocapqa.jobs.runner import JobRunner
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository
from mocapqa.store.shoots import ShootStore

__all__ = ["DEMO_FILES", "DEMO_SHOOT", "DEMO_SHOOT_CORPUS_FILES", "demo_paths", "load_demo"]

DEMO_FILES = ("cmu_12_01_walk_twist_errors.bvh", "pose2sim_S00_P00_T01_BalancingTrial.trc")
"""File names of the demo takes in ``mocapqa/data/demo``, in loading order."""
DEMO_SHOOT = "Demo shoot"
"""Name of the demo shoot."""
DEMO_SHOOT_CORPUS_FILES = (
    "bvh/cmu/cmu_12_01_walk.bvh",
    "bvh/misc/AV_8Walk_Meredith_HVHA_Rep1.bvh",
    "keypoints/pose2sim/S00_P00_T00_StaticTrial/pose-3d/S00_P00_T00_StaticTrial_0-12.trc",
    "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/"
    "S00_P00_T01_BalancingTrial_0-100_filt_butterworth.trc",
)
"""Corpus takes added to the demo shoot when the corpus is found."""
log = logging.getLogger(__name__)


def demo_paths() -> list[Path]:
    """The bundled demo files that exist, in :data:`DEMO_FILES` order."""
    folder = resources.files("mocapqa") / "data" / "demo"
    paths = [Path(str(folder / name)) for name in DEMO_FILES]
    return [p for p in paths if p.is_file()]


def _shoot_paths() -> list[Path]:
    corpus = find_corpus()
    extra = [corpus / name for name in DEMO_SHOOT_CORPUS_FILES] if corpus is not None else []
    return demo_paths() + [p for p in extra if p.is_file()]


def load_demo(
    repository: Repository, files: FileStore, runner: JobRunner, timeout_s: float = 120.0
) -> list[str]:
    """Load and analyse the demo takes and the demo shoot when there are no takes yet; returns
    the new take ids (single takes first)."""
    _, total = repository.list_takes(limit=1)
    if total:
        return []
    shoot_id = str(ShootStore(repository.engine).ensure(DEMO_SHOOT)["id"])
    take_ids = []
    for path, shoot in [(p, None) for p in demo_paths()] + [(p, shoot_id) for p in _shoot_paths()]:
        with path.open("rb") as handle:
            take_id, run_id = ingest_take(
                handle, path.name, repository, files, runner, 1 << 30, shoot_id=shoot
            )
        runner.wait(run_id, timeout_s)
        take_ids.append(take_id)
        log.info("demo take %s loaded%s", path.name, " into the demo shoot" if shoot else "")
    return take_ids
