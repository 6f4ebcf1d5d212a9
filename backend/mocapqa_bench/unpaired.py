"""The unpaired-burst figures: a natural roll step followed by a burst that does not cancel.

Each bench take gets :func:`mocapqa.twist.inject_unpaired.inject_unpaired_bursts` (seeded like
the level-shift injections, from ``(seed, crc32(file name), repeat)``) and is refined; the
figures are those measured on the real errors of ``005_05``
(:func:`mocapqa_bench.natural.natural_error_figures`): counter-rotated roll jumps over 20°
removed, and frame × chain cells farther than 0.25 s from every such jump whose roll was moved
by more than 5°.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from mocapqa.io.bvh import read_bvh
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.detect import RobustParams
from mocapqa.twist.inject_unpaired import inject_unpaired_bursts
from mocapqa_bench.natural import natural_error_figures
from mocapqa_bench.twist import (
    RIGS,
    BenchFile,
    IntervalRecord,
    interval_records,
    seeded_injections,
)

__all__ = ["UnpairedTotals", "run_unpaired_bench", "unpaired_totals"]


@dataclass(frozen=True, slots=True)
class UnpairedTotals:
    """Summed figures of the unpaired-burst injections of a set of takes.

    Parameters
    ----------
    n_injected : int
        Injected takes.
    n_jumps, n_removed : int
        Counter-rotated roll jumps over 20° and how many the refinement removed.
    n_far_cells, n_far_moved : int
        Cells farther than 0.25 s from every such jump, and those moved by more than 5°.
    n_takes_moved : int
        Injected takes with at least one such far move.
    max_far_move_deg : float
        Largest far move, degrees.
    """

    n_injected: int
    n_jumps: int
    n_removed: int
    n_far_cells: int
    n_far_moved: int
    n_takes_moved: int
    max_far_move_deg: float


Key = tuple[str, bool, str, int]
"""``(rig, held_out, take, repeat)``."""


def run_unpaired_bench(
    files: Sequence[BenchFile],
    params: RobustParams | None = None,
    seed: int = 0,
    repeats: int = 2,
    apply: str = "confident",
    on_file: Callable[[BenchFile], None] | None = None,
    records: list[IntervalRecord] | None = None,
) -> dict[Key, UnpairedTotals]:
    """Inject unpaired bursts into every take, refine with the robust method and measure.

    Parameters
    ----------
    files : sequence of BenchFile
    params : RobustParams, optional
        Detector parameters (defaults when omitted).
    seed : int
        Base seed; each injection uses ``(seed, crc32(file name), repeat)``.
    repeats : int
        Injections per take.
    apply : str
        The apply choice of the refinement.
    on_file : callable, optional
        Called after each take (progress).
    records : list of IntervalRecord, optional
        When given, every interval found is appended to it, labelled right or wrong against
        the injected burst like the other injections' intervals (for the calibration).

    Returns
    -------
    dict
        ``(rig, held_out, take, repeat)`` → the figures of that injected take (takes too short
        for the shape are left out).
    """
    out: dict[Key, UnpairedTotals] = {}
    for bench_file in files:
        motion = read_bvh(bench_file.path)
        injections = seeded_injections(motion, bench_file, seed, repeats, inject_unpaired_bursts)
        for repeat, corrupted, truth in injections:
            analysis = analyze_twist(corrupted, "robust", params=params, apply=apply)
            if records is not None:
                records += interval_records(analysis, truth.offsets_rad, bench_file)
            f = natural_error_figures(corrupted, analysis)
            key = (bench_file.rig, bench_file.held_out, bench_file.path.name, repeat)
            out[key] = UnpairedTotals(1, f.n_jumps, f.n_removed, f.n_far_frames, f.n_far_moved,
                                      int(f.n_far_moved > 0), f.max_far_move_deg)  # fmt: skip
        if on_file is not None:
            on_file(bench_file)
    return out


def unpaired_totals(
    figures: dict[Key, UnpairedTotals],
    rigs: Sequence[str] = RIGS,
    held_out: bool | None = None,
) -> UnpairedTotals:
    """The figures summed over the selected takes (None selects both sets)."""
    chosen = [
        v for (rig, hold, _, _), v in figures.items()
        if rig in rigs and (held_out is None or hold == held_out)
    ]  # fmt: skip
    return UnpairedTotals(
        n_injected=sum(v.n_injected for v in chosen),
        n_jumps=sum(v.n_jumps for v in chosen),
        n_removed=sum(v.n_removed for v in chosen),
        n_far_cells=sum(v.n_far_cells for v in chosen),
        n_far_moved=sum(v.n_far_moved for v in chosen),
        n_takes_moved=sum(v.n_takes_moved for v in chosen),
        max_far_move_deg=max((v.max_far_move_deg for v in chosen), default=0.0),
    )
