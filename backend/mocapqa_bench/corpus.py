"""The benchmarks' view of the real-data corpus (found by :mod:`mocapqa.corpus`)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["corpus_bvh_files"]


def corpus_bvh_files(data_dir: Path) -> list[Path]:
    """Every ``.bvh`` file under ``data_dir``, sorted by path."""
    return sorted(p for p in data_dir.rglob("*.bvh") if p.is_file())
