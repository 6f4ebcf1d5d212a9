"""Fixtures of the render tests: one canvas pool per session (VTK starts once), image checks."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest
from pixels import BROKEN_FRAMES, BROKEN_JOINT
from scipy.spatial.transform import Rotation

from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh

KICK = "bvh/bandai/dataset-1_kick_normal_001.bvh"


@pytest.fixture(scope="session")
def canvases() -> Iterator[object]:
    """A session-wide canvas pool (all render tests run on the main thread)."""
    from mocapqa.render.engine import CanvasPool

    pool = CanvasPool()
    yield pool
    pool.close()


@pytest.fixture(scope="session")
def kick(corpus_dir: Path) -> Motion:
    """Bandai kick (22 joints, 30 fps, Y up)."""
    return read_bvh(corpus_dir / KICK)


@pytest.fixture(scope="session")
def kick_broken(kick: Motion) -> Motion:
    """The kick with a 40° swing added to UpperArm_R on frames 40-70: a known error to fix."""
    joint = kick.skeleton.index(BROKEN_JOINT)
    quats = kick.quats.copy()
    start, end = BROKEN_FRAMES
    error = Rotation.from_euler("z", 40, degrees=True)
    quats[start : end + 1, joint] = (
        Rotation.from_quat(quats[start : end + 1, joint]) * error
    ).as_quat()
    return replace(kick, quats=quats)
