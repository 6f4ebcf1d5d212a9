"""Gap fill on the real gapped take and fill time on a long take.

:func:`twin_figures` fills the corpus' real gapped take (``TWIN_GAPPED``, one marker with the
gaps its system left) and measures the fills against the clean export of the same take
(``TWIN_CLEAN``), next to the expected errors the fill gave. :func:`fill_speed` times
:func:`~mocapqa.markers.fill.fill_gaps` on a 10,000-frame, 60-marker take tiled from real ones
(:func:`mocapqa_bench.markers.tiled_take`) with 5 % of its samples hidden in gaps of
0.05–0.5 s.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import column_runs
from mocapqa.markers.fill import Apply, FillParams, fill_gaps
from mocapqa_bench.marker_fill import load_points
from mocapqa_bench.markers import load_takes, tiled_take

__all__ = ["TWIN_CLEAN", "TWIN_GAPPED", "fill_speed", "twin_figures"]

TWIN_GAPPED = "c3d/optitrack/kinematics_tennis_serve_nan.c3d"
"""The real gapped take, relative to the corpus folder."""

TWIN_CLEAN = "c3d/optitrack/kinematics_tennis_serve.c3d"
"""Its clean twin."""


def twin_figures(
    corpus_dir: Path, apply: Apply = "all", params: FillParams | None = None
) -> dict[str, Any]:
    """Fill RMSE of the real gapped take against its clean twin, and the expected error.

    Parameters
    ----------
    corpus_dir : Path
        The real-data corpus folder.
    apply : {"confident", "all"}
        Which fills are scored.
    params : FillParams, optional
        Fill settings.

    Returns
    -------
    dict
        ``gaps`` (all), ``filled_gaps`` and ``filled_samples`` (applied), ``rmse_mm`` (3-D RMSE
        of the applied fills against the clean take) and ``expected_mm`` (their expected
        errors, root mean square weighted by gap length), ``methods`` (count per method).
    """
    gapped, fps, units_per_mm = load_points(corpus_dir / TWIN_GAPPED)
    clean, _, _ = load_points(corpus_dir / TWIN_CLEAN)
    result = fill_gaps(gapped, fps, params, apply, units_per_mm=units_per_mm)
    applied = [g for g in result.gaps if g.applied]
    mask = result.filled
    samples = int(mask.sum())
    rmse = np.sqrt(np.mean(np.sum((result.positions[mask] - clean[mask]) ** 2, axis=-1)))
    expected = sum(g.expected_error**2 * (g.end - g.start + 1) for g in applied)
    methods: dict[str, int] = {}
    for g in applied:
        methods[str(g.method)] = methods.get(str(g.method), 0) + 1
    return {
        "apply": apply,
        "gaps": len(result.gaps),
        "filled_gaps": len(applied),
        "filled_samples": samples,
        "rmse_mm": float(rmse / units_per_mm) if samples else float("nan"),
        "expected_mm": float(np.sqrt(expected / samples) / units_per_mm) if samples else np.nan,
        "methods": methods,
    }


def fill_speed(
    corpus_dir: Path, params: FillParams | None = None, *, share: float = 0.05, seed: int = 0
) -> dict[str, Any]:
    """CPU and wall time of filling every gap of a 10,000-frame, 60-marker take.

    The take is tiled from the swap bench's second and third takes (as its check speed);
    gaps of 6–60 frames (0.05–0.5 s at 120 Hz) on random markers are hidden until ``share``
    of the samples are missing, its own gaps included. BLAS is pinned to one thread.

    Parameters
    ----------
    corpus_dir : Path
        The real-data corpus folder.
    params : FillParams, optional
        Fill settings.
    share : float
        Share of missing samples.
    seed : int
        Seed of the hidden gaps.

    Returns
    -------
    dict
        ``frames``, ``markers``, ``gaps``, ``missing`` (share), ``cpu_s`` and ``wall_s``.
    """
    from threadpoolctl import threadpool_limits  # type: ignore[import-untyped]

    positions, _ = tiled_take(load_takes(corpus_dir)[1:3])
    rng = np.random.default_rng(seed)
    n, markers, _ = positions.shape
    while np.isnan(positions[..., 0]).mean() < share:
        length = int(rng.integers(6, 61))
        start = int(rng.integers(1, n - length - 1))
        positions[start : start + length, int(rng.integers(markers))] = np.nan
    gaps = int(column_runs(np.isnan(positions[..., 0]))[0].size)
    with threadpool_limits(limits=1, user_api="blas"):
        start_wall, start_cpu = time.perf_counter(), time.process_time()
        fill_gaps(positions, 120.0, params, "all")
        cpu, wall = time.process_time() - start_cpu, time.perf_counter() - start_wall
    return {
        "frames": n,
        "markers": markers,
        "gaps": gaps,
        "missing": float(np.isnan(positions[..., 0]).mean()),
        "cpu_s": cpu,
        "wall_s": wall,
    }
