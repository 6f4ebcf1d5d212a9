"""Where the real-data corpus is: one lookup for the benchmarks, the demo shoot and the tests.

The corpus is the folder holding ``MANIFEST.tsv`` (``shared/data`` beside the checkout). The
order of places looked at matches the test suite's ``corpus_dir`` fixture:
``MOCAPQA_CORPUS_DIR``, then ``MOCAPQA_DATA_DIR``, then ``shared/data`` beside the repository.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from mocapqa.errors import NotFoundError

__all__ = ["CORPUS_VARIABLES", "find_corpus", "require_corpus"]

CORPUS_VARIABLES = ("MOCAPQA_CORPUS_DIR", "MOCAPQA_DATA_DIR")
"""Environment variables naming the corpus folder, in the order they are tried."""
_REPO_ROOT = Path(__file__).resolve().parents[2]


def find_corpus(environ: Mapping[str, str] | None = None) -> Path | None:
    """The corpus folder (the one holding ``MANIFEST.tsv``), or None when none is found.

    Parameters
    ----------
    environ : mapping, optional
        Environment to read :data:`CORPUS_VARIABLES` from; ``os.environ`` by default.
    """
    env = os.environ if environ is None else environ
    candidates = [Path(env[var]) for var in CORPUS_VARIABLES if env.get(var)]
    candidates.append(_REPO_ROOT.parent / "shared" / "data")
    for path in candidates:
        if (path / "MANIFEST.tsv").is_file():
            return path.resolve()
    return None


def require_corpus(data_dir: Path | None = None) -> Path:
    """``data_dir`` if given, else :func:`find_corpus`.

    Raises
    ------
    NotFoundError
        If ``data_dir`` is not a folder or no corpus is found.
    """
    if data_dir is not None:
        if not data_dir.is_dir():
            raise NotFoundError(f"Expected a data folder, got nothing at {data_dir}")
        return data_dir
    found = find_corpus()
    if found is None:
        raise NotFoundError(
            "Expected the motion corpus (MANIFEST.tsv) in $MOCAPQA_CORPUS_DIR, "
            "$MOCAPQA_DATA_DIR or shared/data beside the repository, got none; pass --data"
        )
    return found
