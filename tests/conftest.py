"""Shared fixtures. ``corpus_dir`` is the one way tests reach the real data in ``../shared/data``.

It finds the folder as the benchmarks and the demo shoot do (:func:`mocapqa.corpus.find_corpus`:
``MOCAPQA_CORPUS_DIR``, then ``MOCAPQA_DATA_DIR`` when that folder holds the corpus'
``MANIFEST.tsv``, then ``shared/data`` beside the checkout). A missing corpus fails the test run
loudly: real-data tests are never skipped.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mocapqa.corpus import find_corpus

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def corpus_dir() -> Path:
    """The real motion data (``../shared/data``); fails when it cannot be found."""
    path = find_corpus()
    if path is None:
        pytest.fail(
            "real-data corpus not found: set MOCAPQA_CORPUS_DIR or put shared/data beside the "
            "checkout"
        )
    return path


@pytest.fixture(scope="session")
def bvh_files(corpus_dir: Path) -> list[Path]:
    """Every BVH file of the corpus, sorted."""
    files = sorted(corpus_dir.glob("bvh/**/*.bvh"))
    assert files, f"no BVH files under {corpus_dir}"
    return files


@pytest.fixture(scope="session")
def cmu_walk(corpus_dir: Path) -> Path:
    """The CMU 12_01 walk (31 joints, 120 fps)."""
    return corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh"
