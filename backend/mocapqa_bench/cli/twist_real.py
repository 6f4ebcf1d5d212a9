"""The real-take figures of ``mocapqa bench twist``: natural errors on the real-error takes and
the default refinement of every real take, at its own rate and resampled."""

from __future__ import annotations

from pathlib import Path

from rich.console import Console

from mocapqa_bench.cli.twist_tables import calibration_table, clean_takes_table, natural_table

__all__ = ["print_real"]


def _real_takes(data_dir: Path) -> list[Path]:
    return sorted(p for p in data_dir.rglob("*.bvh") if p.is_file())


def print_real(data_dir: Path, console: Console, methods_chosen: list[str]) -> None:
    """Natural-error figures on the real-error takes and the default refinement of every take."""
    from mocapqa.io.bvh import read_bvh
    from mocapqa.twist.analysis import analyze_twist
    from mocapqa_bench.calibration import real_interval_records, reliability
    from mocapqa_bench.natural import (
        CLEAN_RATES,
        clean_figures_at_rates,
        clean_take_figure,
        natural_error_figures,
    )
    from mocapqa_bench.twist import REAL_ERROR_TAKES

    takes = _real_takes(data_dir)
    for path in (p for p in takes if p.name in REAL_ERROR_TAKES):
        motion = read_bvh(path)
        rows = [
            (f"{m} (apply {a})", natural_error_figures(motion, analyze_twist(motion, m, apply=a)))
            for m in methods_chosen
            for a in (("confident", "all") if m == "robust" else ("all",))
        ]
        console.print(f"{path.parent.name}/{path.name}: {motion.n_frames} frames, {motion.fps} fps")
        console.print(natural_table(rows))
        if "robust" in methods_chosen:
            records = real_interval_records(motion, path.name, "iclone")
            console.print(
                calibration_table(
                    f"Calibration on the real intervals of {path.name} "
                    f"({sum(r.right for r in records)} of {len(records)} right)",
                    reliability([r.confidence for r in records], [r.right for r in records]),
                )
            )
    rows_clean = []
    for path in takes:
        motion = read_bvh(path)
        rows_clean.append((path, (motion, clean_take_figure(motion, analyze_twist(motion)))))
    console.print(clean_takes_table(rows_clean))
    clean_rows = [r for p, r in rows_clean if p.name not in REAL_ERROR_TAKES]
    console.print(
        f"takes without real errors: {len(clean_rows)}, with an interval applied by default: "
        f"{sum(f.n_applied > 0 for _, f in clean_rows)}, intervals applied: "
        f"{sum(f.n_applied for _, f in clean_rows)}, largest change "
        f"{max((f.max_change_deg for _, f in clean_rows), default=0.0):.1f}°"
    )
    spun = [p.name for p, (_, f) in rows_clean if f.n_spins + f.n_flips]
    console.print(
        f"real takes with a limb spin or flip reported (never applied): {len(spun)} of "
        f"{len(rows_clean)}: {', '.join(spun) or 'none'}"
    )
    # The same clean takes at other common frame rates: the decisions should not change.
    resampled = [
        (path.name, fps, figure)
        for path, (motion, _) in rows_clean
        if path.name not in REAL_ERROR_TAKES
        for fps, figure in clean_figures_at_rates(motion)
    ]
    applied = [(name, fps, f) for name, fps, f in resampled if f.n_applied]
    spinning = sorted({name for name, _, f in resampled if f.n_spins + f.n_flips})
    console.print(
        f"takes without real errors resampled to {', '.join(f'{r:g}' for r in CLEAN_RATES)} "
        f"fps: {len(resampled)} take-rates, with an interval applied by default: {len(applied)}; "
        f"with a limb spin or flip: "
        f"{sum(1 for _, _, f in resampled if f.n_spins + f.n_flips)} "
        f"(takes: {', '.join(spinning) or 'none'})"
        + "".join(
            f"\n  {name} at {fps:g} fps: {f.n_applied} applied, largest change "
            f"{f.max_change_deg:.1f}°"
            for name, fps, f in applied
        )
    )
