"""Real takes of the three rigs, read once per session."""

from __future__ import annotations

from pathlib import Path

import pytest

from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh

TAKES = {
    "cmu": "bvh/cmu/cmu_12_01_walk.bvh",
    "iclone": "bvh/cmu/iclone/002_09.bvh",
    "bandai": "bvh/bandai/dataset-2_walk_normal_001.bvh",
}


@pytest.fixture(scope="session")
def takes(corpus_dir: Path) -> dict[str, Motion]:
    """One real take per rig: CMU cgspeed (120 fps), Character Creator, Bandai (30 fps)."""
    return {rig: read_bvh(corpus_dir / path) for rig, path in TAKES.items()}
