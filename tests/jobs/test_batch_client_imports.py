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
