"""The batch client never analyses: importing it must not load the analysis stack (scipy,
numba, the pipeline), which cost a resume of a finished batch about 2 CPU s and the client
about 140 MB of memory (docs/batch.md)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

HEAVY = ("scipy", "numba", "mocapqa.pipeline.analyze", "mocapqa.jobs.runner")


def test_batch_client_loads_no_analysis_stack() -> None:
    backend = Path(__file__).resolve().parents[2] / "backend"
    code = (
        "import json, sys\n"
        "import mocapqa.jobs.batch, mocapqa.jobs.batch_output, mocapqa.store.shoots\n"
        f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(backend)}
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == []


def test_the_task_still_analyses_when_called(corpus_dir: Path) -> None:
    from mocapqa.jobs.take_task import analyse_path
    from mocapqa.pipeline.options import AnalysisOptions

    walk = corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh"
    outcome = analyse_path(str(walk), AnalysisOptions().to_json(), "a" * 32, "b" * 32, None)
    assert outcome["status"] == "done"
    assert outcome["take"]["n_frames"] == 524
    assert 0 <= outcome["summary"]["qa"]["score"] <= 100


def test_a_finished_batch_resumes_without_dask_or_the_analysis_stack(
    corpus_dir: Path, tmp_path: Path
) -> None:
    """Running `mocapqa batch` again over analysed takes skips them all without importing
    distributed, numba or scipy (about 1.5 of the resume's 4 CPU s before; docs/batch.md)."""
    from mocapqa.jobs.batch import run_batch
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore

    folder = tmp_path / "takes"
    folder.mkdir()
    for name in ("cmu_12_01_walk.bvh", "iclone/001_14.bvh"):
        (folder / Path(name).name).symlink_to(corpus_dir / "bvh" / "cmu" / name)
    database = f"sqlite:///{tmp_path / 'db.sqlite3'}"
    repository = Repository(database)
    counts = run_batch(
        [folder], ShootStore(repository.engine), AnalysisOptions(), lambda row: None, None,
        tmp_path / "data",
    )  # fmt: skip
    repository.close()
    assert counts.done == 2
    backend = Path(__file__).resolve().parents[2] / "backend"
    env = {
        **os.environ,
        "PYTHONPATH": str(backend),
        "MOCAPQA_DATABASE_URL": database,
        "MOCAPQA_DATA_DIR": str(tmp_path / "data"),
        "MOCAPQA_DASK_SCHEDULER": "",
    }
    output = tmp_path / "again.jsonl"
    command = [sys.executable, "-X", "importtime", "-m", "mocapqa.cli.main", "batch"]
    done = subprocess.run(
        [*command, str(folder), "--workers", "2", "--output", str(output)],
        env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    rows = [json.loads(line) for line in output.read_text().splitlines()]
    assert [row["status"] for row in rows] == ["skipped", "skipped"]
    imported = {line.rsplit("|", 1)[-1].strip() for line in done.stderr.splitlines()}
    assert {"distributed", "numba", "scipy"} & imported == set()
