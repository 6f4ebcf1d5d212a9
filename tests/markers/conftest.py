"""Real marker takes for the marker tests, read through one helper (:func:`load_take`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

from mocapqa.core.arrays import FloatArray
from mocapqa.io.c3d import read_c3d

CLEAN_TAKES = (
    "optitrack/kinematics_tennis_serve.c3d",
    "cmu/cmu_02_05.c3d",
    "vicon/nick_freeform_001.c3d",
)
"""Takes without swaps (the clean takes of the corpus README)."""


@dataclass(frozen=True)
class Take:
    """A marker take's arrays: positions ``(F, M, 3)`` (NaN where missing), labels, rate, unit."""

    positions: FloatArray
    names: tuple[str, ...]
    fps: float
    length_unit: str


def load_take(path: Path) -> Take:
    """Read a C3D take through :func:`mocapqa.io.c3d.read_c3d` (NaN where missing)."""
    points = read_c3d(path).points
    return Take(points.positions, points.names, points.fps, points.length_unit)


@pytest.fixture(scope="session")
def c3d_dir(corpus_dir: Path) -> Path:
    """The corpus' C3D folder."""
    return corpus_dir / "c3d"


@pytest.fixture(scope="session")
def clean_takes(c3d_dir: Path) -> dict[str, Take]:
    """The clean takes, by corpus path under ``c3d/``."""
    return {name: load_take(c3d_dir / name) for name in CLEAN_TAKES}
