"""Tables of ``mocapqa bench twist``: the paper's Tables 1 and 2, the ablation, and beyond the
paper's: real errors, clean takes, calibration, leave-one-rig-out figures, each rate with its
confidence interval."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from rich.table import Table

__all__ = [
    "SEGMENTS",
    "ablation_table",
    "calibration_table",
    "clean_takes_table",
    "disagreement_table",
    "ends_table",
    "loro_table",
    "loro_variants",
    "natural_levels_table",
    "natural_table",
    "paper_table1",
    "paper_table2",
    "rates_table",
    "rows_table",
    "small_offsets_table",
    "unpaired_table",
]


SEGMENTS = ("clavicle", "upper_arm", "forearm", "upper_leg", "lower_leg")
"""The segments of the per side × segment figures, in table order."""


def paper_table1(methods: dict[str, Any]) -> Table:
    """The paper's Table 1: rotation error of the target joints per rig and set, per method."""
    from mocapqa_bench.twist import RIGS

    groups: list[tuple[str, tuple[str, ...], bool | None]] = [
        *[(rig, (rig,), None) for rig in RIGS],
        ("all", RIGS, None),
        ("all: fit set", RIGS, False),
        ("all: held-out", RIGS, True),
    ]
    table = Table(title="Table 1: rotation error of the target joints on the error frames")
    for column in ("set", "method", "frames", "MAE before °", "MAE after °", "RMSE before °",
                   "RMSE after °", "FSR %", "clean >1° %", "clean max °", "frames/s"):  # fmt: skip
        table.add_column(column, justify="left" if column in ("set", "method") else "right")
    for name, rigs, held in groups:
        for label, res in methods.items():
            acc = res.accuracy(rigs, held)
            clean = res.clean_figure(rigs, held)
            table.add_row(
                name, label, str(acc.n_frames), f"{acc.mae_before_deg:.2f}",
                f"{acc.mae_after_deg:.2f}", f"{acc.rmse_before_deg:.2f}",
                f"{acc.rmse_after_deg:.2f}", f"{100 * acc.fsr:.2f}", f"{100 * clean.share:.4f}",
                f"{clean.max_change_deg:.1f}",
                "" if held is not None else f"{res.speed(rigs):,.0f}",
            )  # fmt: skip
    return table


def paper_table2(label: str, res: Any) -> Table:
    """The paper's Table 2 for one method: MAE after, RER and FSR per side × segment."""
    from mocapqa_bench.twist import RIGS

    table = Table(title=f"Table 2 ({label}): per side × segment — MAE after ° / RER / FSR %")
    table.add_column("segment")
    table.add_column("side")
    sets = [("all", RIGS), *[(rig, (rig,)) for rig in RIGS]]
    for name, _ in sets:
        table.add_column(name, justify="right")
    for segment in SEGMENTS:
        for side in ("left", "right"):
            cells = []
            for _, rigs in sets:
                acc = res.accuracy(rigs, None, side, segment)
                cells.append(
                    f"{acc.mae_after_deg:.2f} / {acc.rer:.3f} / {100 * acc.fsr:.1f}"
                    if acc.n_frames
                    else "–"
                )
            table.add_row(segment, side, *cells)
    return table


def ablation_table(methods: dict[str, Any]) -> Table:
    """The robust method with one idea changed per row, over all rigs."""
    table = Table(title="Ablation (all rigs): the robust method with one idea changed")
    for column in ("variant", "FSR %", "fit FSR %", "held-out FSR %", "worst side×segment FSR %",
                   "MAE after °", "RMSE after °", "clean >1° %", "clean max °"):  # fmt: skip
        table.add_column(column, justify="left" if column == "variant" else "right")
    for label, res in methods.items():
        acc = res.accuracy()
        per_segment = [
            res.accuracy(side=side, segment=segment)
            for side in ("left", "right")
            for segment in SEGMENTS
        ]
        worst = min((100 * a.fsr for a in per_segment if a.n_frames), default=float("nan"))
        clean = res.clean_figure()
        table.add_row(
            label, f"{100 * acc.fsr:.2f}", f"{100 * res.accuracy(held_out=False).fsr:.2f}",
            f"{100 * res.accuracy(held_out=True).fsr:.2f}", f"{worst:.1f}",
            f"{acc.mae_after_deg:.2f}", f"{acc.rmse_after_deg:.2f}",
            f"{100 * clean.share:.4f}", f"{clean.max_change_deg:.1f}",
        )  # fmt: skip
    return table


def _pct(low: float, high: float) -> str:
    return f"[{100 * low:.1f}, {100 * high:.1f}]"


def rates_table(methods: dict[str, Any]) -> Table:
    """FSR with a 95 % bootstrap interval over takes, MAE, clean changes and spill per set."""
    from mocapqa_bench.twist import RIGS

    table = Table(title="FSR with 95 % bootstrap intervals over takes; spill onto clean frames")
    for column in ("set", "method", "takes", "FSR %", "95 % CI", "MAE after °",
                   "clean >1° %", "spill max °"):  # fmt: skip
        table.add_column(column, justify="left" if column in ("set", "method") else "right")
    groups: list[tuple[str, tuple[str, ...], bool | None]] = [
        *[(rig, (rig,), None) for rig in RIGS],
        ("all", RIGS, None),
        ("all: fit set", RIGS, False),
        ("all: held-out", RIGS, True),
    ]
    for name, rigs, held in groups:
        for label, res in methods.items():
            acc = res.accuracy(rigs, held)
            takes = sum(
                1 for (rig, hold, _), v in res.per_take.items()
                if rig in rigs and (held is None or hold == held) and v[1]
            )  # fmt: skip
            table.add_row(
                name, label, str(takes), f"{100 * acc.fsr:.2f}",
                _pct(*res.bootstrap_fsr(rigs, held)), f"{acc.mae_after_deg:.2f}",
                f"{100 * res.clean_figure(rigs, held).share:.4f}",
                f"{res.max_spill(rigs, held):.1f}",
            )  # fmt: skip
    return table


def ends_table(rows: Sequence[tuple[str, str, Any]]) -> Table:
    """Errors at a take's ends per (where, apply, MethodResult): per rig on the held-out takes,
    then all held-out and all fit takes. FSR is over every injected error frame of those takes;
    an end interval is detected when an interval found on its joint covers half of its frames,
    corrected when at most 20 % of its rotation error is left."""
    from mocapqa_bench.twist import RIGS

    table = Table(title="Errors at the take's ends (one level shift per target starts on the first "
                  "frame of motion, head, or ends on the last frame, tail)")  # fmt: skip
    for column in ("end", "apply", "set", "takes", "FSR %", "95 % CI", "end intervals",
                   "detected %", "corrected %", "clean >1° %", "spill max °"):  # fmt: skip
        table.add_column(column, justify="left" if column in ("end", "apply", "set") else "right")
    groups: list[tuple[str, tuple[str, ...], bool]] = [
        *[(f"{rig}: held-out", (rig,), True) for rig in RIGS],
        ("all: held-out", RIGS, True),
        ("all: fit set", RIGS, False),
    ]
    for where, apply, res in rows:
        for name, rigs, held in groups:
            acc = res.accuracy(rigs, held)
            n, detected, corrected = res.end_counts(rigs, held)
            takes = sum(
                1 for (rig, hold, _), v in res.per_take.items()
                if rig in rigs and hold == held and v[1]
            )  # fmt: skip
            table.add_row(
                where, apply, name, str(takes), f"{100 * acc.fsr:.2f}",
                _pct(*res.bootstrap_fsr(rigs, held)), str(n),
                f"{100 * detected / n:.1f}" if n else "–",
                f"{100 * corrected / n:.1f}" if n else "–",
                f"{100 * res.clean_figure(rigs, held).share:.4f}",
                f"{res.max_spill(rigs, held):.1f}",
            )  # fmt: skip
    return table


def natural_table(rows: Sequence[tuple[str, Any]]) -> Table:
    """Real-error figures per (label, NaturalErrorFigures)."""
    from mocapqa_bench.natural import wilson_interval

    table = Table(title="Real errors (005_05): counter-rotated roll jumps over 20°")
    for column in ("refinement", "jumps", "removed (step < 20°)", "95 % Wilson",
                   "step ≤ 5°", "far cells", "far moved > 5°", "far max move °"):  # fmt: skip
        table.add_column(column, justify="left" if column == "refinement" else "right")
    for label, f in rows:
        share = f.n_removed / f.n_jumps if f.n_jumps else 0.0
        table.add_row(
            label, str(f.n_jumps), f"{f.n_removed} ({100 * share:.1f} %)",
            _pct(*wilson_interval(f.n_removed, f.n_jumps)), str(f.n_removed_strict),
            str(f.n_far_frames), str(f.n_far_moved), f"{f.max_far_move_deg:.1f}",
        )  # fmt: skip
    return table


def clean_takes_table(rows: Sequence[tuple[Path, Any]]) -> Table:
    """Intervals found and applied by default, and the largest change, per real take."""
    table = Table(title="Real takes refined with the defaults (apply = confident)")
    for column in (
        "take", "frames", "fps", "intervals found", "applied", "max change °",
        "limb spins / flips (reported)",
    ):  # fmt: skip
        table.add_column(column, justify="left" if column == "take" else "right")
    for path, (motion, figure) in rows:
        table.add_row(
            f"{path.parent.name}/{path.name}", str(motion.n_frames), f"{motion.fps:.0f}",
            str(figure.n_intervals), str(figure.n_applied), f"{figure.max_change_deg:.1f}",
            f"{figure.n_spins} / {figure.n_flips}",
        )  # fmt: skip
    return table


def calibration_table(title: str, bins: Sequence[Any]) -> Table:
    """A reliability table: predicted probability against the observed share of right ones."""
    table = Table(title=title)
    for column in ("probability", "intervals", "mean predicted", "observed right"):
        table.add_column(column, justify="right")
    for b in bins:
        table.add_row(
            f"[{b.low:.1f}, {b.high:.1f}{']' if b.high >= 1.0 else ')'}",
            str(b.count),
            "–" if not b.count else f"{b.mean_probability:.3f}",
            "–" if not b.count else f"{b.right_share:.3f}",
        )
    return table


def loro_variants() -> dict[str, Any]:
    """The parameter grid of the leave-one-rig-out table (robust method, defaults first)."""
    from mocapqa.twist.detect import RobustParams

    base = RobustParams()
    return {
        "defaults": base,
        "noise factor 6": replace(base, noise_factor=6.0),
        "noise factor 11": replace(base, noise_factor=11.0),
        "consistency 0.35": replace(base, consistency=0.35),
        "burst gap 0.05 s": replace(base, burst_gap_s=0.05),
    }


def loro_table(grid: dict[str, Any]) -> Table:
    """Per held-out rig: the variant with the best FSR on the other two, and its FSR there."""
    from mocapqa_bench.twist import RIGS

    table = Table(title="Leave one rig out: parameters chosen on two rigs, FSR on the third")
    for column in ("held-out rig", "chosen on", "variant chosen", "FSR on the two %",
                   "FSR held-out rig %", "95 % CI", "MAE after °"):  # fmt: skip
        table.add_column(column, justify="left" if column in ("variant chosen",) else "right")
    for rig in RIGS:
        others = tuple(r for r in RIGS if r != rig)
        if not any(grid[v].accuracy((rig,)).n_frames for v in grid):
            continue
        chosen = max(grid, key=lambda v: grid[v].accuracy(others).fsr)
        res = grid[chosen]
        acc = res.accuracy((rig,))
        table.add_row(
            rig, "+".join(others), chosen, f"{100 * res.accuracy(others).fsr:.2f}",
            f"{100 * acc.fsr:.2f}", _pct(*res.bootstrap_fsr((rig,))),
            f"{acc.mae_after_deg:.2f}",
        )  # fmt: skip
    return table


def disagreement_table(rows: Sequence[Any]) -> Table:
    """The ``MAX_DISAGREEMENT`` rule chosen on two rigs, checked on the third."""
    table = Table(title="Disagreement limit chosen on two rigs (blocks no right interval there)")
    for column in ("held-out rig", "limit chosen", "right blocked", "wrong blocked",
                   "right applied without it", "wrong applied without it"):  # fmt: skip
        table.add_column(column, justify="right")
    for row in rows:
        table.add_row(
            row.rig, "–" if row.chosen is None else f"{row.chosen:.2f}", str(row.right_blocked),
            str(row.wrong_blocked), str(row.right_applied), str(row.wrong_applied),
        )  # fmt: skip
    return table


def unpaired_table(figures: dict[Any, Any]) -> Table:
    """Unpaired bursts after a natural step: jumps removed and far cells moved, per set."""
    from mocapqa_bench.natural import wilson_interval
    from mocapqa_bench.twist import RIGS
    from mocapqa_bench.unpaired import unpaired_totals

    table = Table(
        title="Unpaired bursts after a natural roll step (injected; figures as on 005_05)"
    )
    for column in ("set", "injected takes", "jumps > 20°", "removed", "95 % Wilson",
                   "far cells", "far moved > 5°", "takes with a far move",
                   "far max move °"):  # fmt: skip
        table.add_column(column, justify="left" if column == "set" else "right")
    groups: list[tuple[str, tuple[str, ...], bool | None]] = [
        *[(rig, (rig,), None) for rig in RIGS],
        ("all", RIGS, None),
        ("all: fit set", RIGS, False),
        ("all: held-out", RIGS, True),
    ]
    for name, rigs, held in groups:
        t = unpaired_totals(figures, rigs, held)
        if not t.n_injected:
            continue
        share = t.n_removed / t.n_jumps if t.n_jumps else 0.0
        table.add_row(
            name, str(t.n_injected), str(t.n_jumps), f"{t.n_removed} ({100 * share:.1f} %)",
            _pct(*wilson_interval(t.n_removed, t.n_jumps)), str(t.n_far_cells),
            str(t.n_far_moved), str(t.n_takes_moved), f"{t.max_far_move_deg:.1f}",
        )  # fmt: skip
    return table


def natural_levels_table(clean: dict[str, Any], fitted: Any) -> Table:
    """The detector's event jumps on clean takes per rig family (and segment): how many, their
    95th and 99th percentiles over every clean take, and the level the rule uses (fit takes)."""
    import numpy as np

    table = Table(
        title="Natural roll on clean takes: the robust detector's event jumps (defaults), by rig; "
        "the rule's level is the p99 on the clean fit takes"
    )
    for column in ("rig / segment", "events", "p95 °", "p99 °", "largest °", "rule level (fit) °"):
        table.add_column(column, justify="left" if column == "rig / segment" else "right")
    known = ("cmu", "character_creator", "bandai")
    others = sorted({k.split("/")[0] for k in clean} - set(known))
    for family in (*known, *others):
        keys = sorted(k for k in clean if k.startswith(family + "/"))
        jumps = np.concatenate([clean[k] for k in keys]) if keys else np.zeros(0)
        stored = any(k in fitted.levels_deg for k in keys)
        rows = [(family, jumps, "per segment:" if stored else "")]
        rows += [(f"  {k.split('/')[1]}", clean[k],
                  f"{fitted.levels_deg[k]:.1f}" if k in fitted.levels_deg else "")
                 for k in keys]  # fmt: skip
        for label, values, level in rows:
            cells = (
                [f"{v:.1f}" for v in (*np.percentile(values, [95.0, 99.0]), values.max())]
                if len(values)
                else ["—", "—", "—"]
            )
            table.add_row(label, str(len(values)), *cells, level or "— (5.0 minimum)")
    return table


def small_offsets_table(rows: Sequence[Any]) -> Table:
    """Injected level shifts by rig and offset band: distinguishable from natural roll, found,
    applied by default and corrected, without → with the natural roll rule."""
    table = Table(
        title="Small offsets, held-out takes, default settings: injected level shifts by offset "
        "band (before → after the natural roll rule)"
    )
    for column in ("rig", "offset band", "injected", "distinguishable", "found",
                   "applied (default)", "not distinguishable, applied", "FSR %"):  # fmt: skip
        table.add_column(column, justify="left" if column in ("rig", "offset band") else "right")
    for r in rows:
        low, high = r.band
        band = f"> {low:g}°" if high >= 180.0 else f"{low:g}–{high:g}°"

        def pct(n: int, total: int = r.frames) -> str:
            return f"{100 * n / total:.1f}" if total else "—"

        table.add_row(
            r.rig, band, str(r.injected), str(r.distinguishable), str(r.found),
            f"{r.applied_before} → {r.applied}", f"{r.hidden_applied_before} → {r.hidden_applied}",
            f"{pct(r.corrected_before)} → {pct(r.corrected)}",
        )  # fmt: skip
    return table


def rows_table(title: str, rows: Sequence[dict[str, Any]]) -> Table:
    """A table of plain rows (one column per key of the first row; floats to 4 figures)."""
    table = Table(title=title, title_justify="left")
    columns = list(rows[0]) if rows else ["(none)"]
    for column in columns:
        table.add_column(str(column), justify="left" if column == columns[0] else "right")
    for row in rows:
        table.add_row(
            *(f"{row[c]:.4g}" if isinstance(row.get(c), float) else str(row.get(c, "–"))
              for c in columns)
        )  # fmt: skip
    return table
