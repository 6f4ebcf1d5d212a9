"""A finished run's twist intervals as its report scored them, kept per report file.

A shoot's reviewer prior (:func:`mocapqa.jobs.shoot_prior.shoot_prior`) reads the twist
intervals of every decided run of the shoot, for each run it queues; each report is read once
per version of its file (path, size and modification time) for the process's life.
"""

from __future__ import annotations

import functools
from pathlib import Path

from mocapqa.jobs.run_folder import RunFolder
from mocapqa.jobs.stored_run import load_report
from mocapqa.store.decisions import CALIBRATED_METHOD
from mocapqa.store.files import FileStore

__all__ = ["twist_items_of"]


def twist_items_of(files: FileStore, run_id: str) -> dict[int, tuple[str, float]]:
    """A finished run's twist intervals: id → (joint, calibrated probability as the run
    scored it), from its report's findings (empty for a run without twist findings, a run of
    a twist method other than :data:`~mocapqa.store.decisions.CALIBRATED_METHOD`, whose
    ``confidence`` is no calibrated probability, or a run whose report cannot be read). A
    shoot's every run reads those of all its decided runs, so they are kept per report file
    (path, size and modification time) for the process's life."""
    path = RunFolder.of(files, run_id).report
    try:
        stat = path.stat()
    except OSError:
        return {}
    return dict(_twist_items(str(path), stat.st_size, stat.st_mtime_ns))


@functools.lru_cache(maxsize=4096)
def _twist_items(
    path: str, size: int, modified_ns: int
) -> tuple[tuple[int, tuple[str, float]], ...]:
    """:func:`twist_items_of` of one report file version (``size`` and ``modified_ns`` only
    key the cache)."""
    try:
        report = load_report(Path(path))
    except (OSError, ValueError):
        return ()
    options = report.get("options")
    method = options.get("twist_method") if isinstance(options, dict) else None
    if method not in (None, CALIBRATED_METHOD):
        return ()
    findings = report.get("findings") or []
    return tuple(
        (int(f["id"]), (str(f["joint"]), float(f.get("confidence") or 0.0)))
        for f in findings
        if isinstance(f, dict) and f.get("kind") == "twist" and "id" in f
    )
