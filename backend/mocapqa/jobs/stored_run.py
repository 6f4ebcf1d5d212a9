"""A finished run read back from its folder: its report (``report.json``) and its point
arrays (``points.npz``), from the files or from the bytes a worker sends back.

The paths are :class:`~mocapqa.jobs.run_folder.RunFolder`'s; the files are written by
:func:`mocapqa.jobs.run_outputs.write_outputs`.
"""

from __future__ import annotations

import io
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.errors import InputError, NotFoundError
from mocapqa.jobs.run_folder import POINTS_NPZ, REPORT_JSON, RunFolder

__all__ = ["StoredRun", "load_points", "load_report", "read_run"]


@dataclass(frozen=True)
class StoredRun:
    """A finished run as stored: its report and its raw and corrected positions.

    Attributes
    ----------
    folder : Path
        The run's folder.
    report : dict
        The report JSON.
    raw, corrected : ndarray, shape (F, P, 3)
        Positions in file units, float64, NaN where missing.
    """

    folder: Path
    report: dict[str, Any]
    raw: np.ndarray
    corrected: np.ndarray


def load_report(source: Path | bytes) -> dict[str, Any]:
    """A run's report from its file (or the file's bytes).

    Raises
    ------
    OSError, ValueError
        When it is missing or not JSON.
    """
    data = source if isinstance(source, bytes) else source.read_bytes()
    report: dict[str, Any] = json.loads(data)
    return report


def load_points(source: Path | bytes, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Arrays ``names`` of a run's points (its file, or the file's bytes), as stored
    (:data:`~mocapqa.jobs.run_folder.POINT_ARRAYS`).

    Raises
    ------
    OSError, ValueError, KeyError
        When the file is missing, unreadable or lacks an array.
    """
    opened = io.BytesIO(source) if isinstance(source, bytes) else source
    with np.load(opened) as data:
        return {name: data[name] for name in names}


def read_run(folder: Path) -> StoredRun:
    """A stored run's report and positions (``report.json`` and ``points.npz``).

    Raises
    ------
    NotFoundError
        When either file is missing.
    InputError
        When they cannot be read.
    """
    run = RunFolder(folder)
    try:
        report = load_report(run.report)
        points = load_points(run.points, ("raw", "corrected"))
    except FileNotFoundError as e:
        raise NotFoundError(
            f"Expected a run folder with {REPORT_JSON} and {POINTS_NPZ}, got {e.filename}"
        ) from e
    except (OSError, ValueError, KeyError) as e:
        raise InputError(f"{folder}: Expected a readable run report and points, got {e}") from e
    raw, corrected = (np.asarray(points[n], dtype=np.float64) for n in ("raw", "corrected"))
    return StoredRun(folder, report, raw, corrected)
