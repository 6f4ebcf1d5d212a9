"""``mocapqa bench limits``: the canonical model per rig and left out, the per-rig models."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from mocapqa.cli.app import bench_app

__all__ = ["bench_limits"]

console = Console(highlight=False)


def _pct(value: float) -> str:
    return "—" if math.isnan(value) else f"{100 * value:.2f}"


def _ci(value: float, interval: tuple[float, float]) -> str:
    return f"{_pct(value)} [{_pct(interval[0])}–{_pct(interval[1])}]"


@bench_app.command("limits")
def bench_limits(
    corpus_dir: Annotated[Path, typer.Argument(help="Corpus folder (shared/data).")],
    rig: Annotated[str | None, typer.Option(help="Per-rig part: only this rig family.")] = None,
    networks: Annotated[bool, typer.Option(help="Train and measure the discriminators.")] = True,
    min_offset_deg: Annotated[float, typer.Option(help="Smallest injected offset.")] = 60.0,
    seed: Annotated[int, typer.Option(help="Seed of the injected errors.")] = 0,
    shipped: Annotated[
        bool, typer.Option(help="Measure the shipped models (built on the same split).")
    ] = True,
    per_rig: Annotated[
        bool,
        typer.Option(help="Also the per-rig models' own benchmark (networks, speeds)."),
    ] = False,
    joint_margins: Annotated[
        bool,
        typer.Option(
            "--joint-margins",
            help="Only the experiment of per-joint twist margins chosen by nested "
            "leave-one-rig-out (docs/limits.md).",
        ),
    ] = False,
    margin_rule: Annotated[
        str,
        typer.Option(help="--joint-margins: inner false flags averaged ('mean') or worst rig."),
    ] = "mean",
    model_path: Annotated[
        Path | None,
        typer.Option(
            "--model",
            help="Measure this canonical model file instead of the shipped one (built on the "
            "same build takes, e.g. by `mocapqa limits build CORPUS --exclude 005_05.bvh`).",
        ),
    ] = None,
    leave_one_out: Annotated[
        bool,
        typer.Option(
            help="Also the leave-one-rig-out tables (maps built without each rig: they do not "
            "depend on the model measured)."
        ),
    ] = True,
) -> None:
    """Canonical model per rig and leave-one-rig-out; optionally the per-rig models."""
    if joint_margins:
        _bench_joint_margins(corpus_dir, seed, margin_rule)
        return
    _bench_canonical(corpus_dir, shipped, seed, min_offset_deg, model_path, leave_one_out)
    if per_rig:
        _bench_per_rig(corpus_dir, rig, networks, min_offset_deg, seed, shipped)


def _bench_joint_margins(corpus_dir: Path, seed: int, rule: str) -> None:
    from mocapqa.bench.limits import role_takes
    from mocapqa.bench.limits_margins import nested_margins
    from mocapqa.core.motion import Motion
    from mocapqa.limits.rig import rig_family

    grouped: dict[str, list[tuple[str, Motion]]] = {}
    for name, motion in role_takes(corpus_dir):
        grouped.setdefault(rig_family(motion.skeleton), []).append((name, motion))
    rigs = {family: tuple(takes) for family, takes in grouped.items()}
    results = nested_margins(rigs, seed=seed, rule=rule)
    table = Table(
        title=f"leave one rig out: per-joint twist margins (nested, rule {rule}) vs 40° everywhere"
    )
    for column in (
        "left-out rig", "false flags % (per joint / 40°)", "injected flagged % (per joint / 40°)",
        "margins chosen on the other rigs (°)",
    ):  # fmt: skip
        table.add_column(column)
    for fold in results:
        recall = fold.hits / max(fold.injected, 1)
        uniform = fold.uniform_hits / max(fold.injected, 1)
        table.add_row(
            fold.family,
            f"{_pct(fold.false_flags)} / {_pct(fold.uniform_false_flags)}",
            f"{_pct(recall)} / {_pct(uniform)} (n={fold.injected})",
            ", ".join(f"{role} {m:g}" for role, m in fold.margins_deg.items()),
        )
    console.print(table)
    mean = sum(f.false_flags for f in results) / len(results)
    mean_uniform = sum(f.uniform_false_flags for f in results) / len(results)
    console.print(
        f"mean false flags over left-out rigs: {_pct(mean)} % (40° everywhere: "
        f"{_pct(mean_uniform)} %)"
    )


def _bench_canonical(
    corpus_dir: Path, shipped: bool, seed: int, min_offset_deg: float,
    model_path: Path | None = None, leave_one_out: bool = True,
) -> None:  # fmt: skip
    from dataclasses import replace

    from mocapqa.bench.limits import canonical_takes, corpus_rigs, role_takes
    from mocapqa.bench.limits_canonical import (
        EVALUATION_ONLY,
        bootstrap_interval,
        canonical_speed,
        count_takes,
        leave_one_rig_out,
    )
    from mocapqa.core.motion import Motion
    from mocapqa.errors import InputError
    from mocapqa.limits.build import DEFAULT_BUILD, build_canonical_model, build_model
    from mocapqa.limits.rig import rig_family
    from mocapqa.limits.storage import default_model_paths, load_model
    from mocapqa.twist.spin import find_limb_spins

    build_takes = canonical_takes(corpus_dir, exclude=EVALUATION_ONLY)
    names = tuple(n for n, _ in build_takes)
    model = None
    if model_path is not None:
        model = load_model(model_path)
        if model.frame != "canonical" or model.takes != names:
            raise InputError(
                f"Expected a canonical model built on the {len(names)} build takes of "
                f"{corpus_dir}, got a {model.frame} model of {len(model.takes)} takes in "
                f"{model_path}"
            )
    elif shipped:
        for path in default_model_paths():
            candidate = load_model(path)
            if candidate.frame == "canonical" and candidate.takes == names:
                model = candidate
    map_only = replace(DEFAULT_BUILD, discriminator=None)
    if model is None:
        console.print("canonical model: built now (map only)")
        model = build_canonical_model([m for _, m in build_takes], list(names), map_only)
    elif model_path is not None:
        console.print(f"canonical model: {model_path} (same build takes)")
    else:
        console.print("canonical model: the shipped one (same build takes)")
    occ = model.occupancy_params
    console.print(
        f"map: bin {occ.bin_deg}°, dilation {occ.dilation_bins}, twist margin "
        f"{occ.tau_margin_deg}°, interpolated {occ.interpolate}; {len(names)} build takes; "
        f"injected offsets {min_offset_deg:.0f}–180°, seed {seed}; [95 % bootstrap over takes]"
    )
    rigs = corpus_rigs(corpus_dir)
    table = Table(title="held-back takes per rig: canonical model vs the rig's own map")
    for column in (
        "rig", "held-back takes", "canonical false flags %", "canonical injected flagged %",
        "rig map false flags %", "rig map injected flagged %",
    ):  # fmt: skip
        table.add_column(column)
    per_joint: dict[str, tuple[dict[str, float], dict[str, float]]] = {}
    unspun_notes = []
    for rig_takes in rigs:
        canon = count_takes(model, rig_takes.held_back, seed, min_offset_deg)
        own_build = [t for t in rig_takes.build if t[0] not in EVALUATION_ONLY]
        own = build_model([m for _, m in own_build], [n for n, _ in own_build], map_only)
        mine = count_takes(own, rig_takes.held_back, seed, min_offset_deg)
        table.add_row(
            rig_takes.family,
            str(sum(1 for n, _ in rig_takes.held_back if n not in EVALUATION_ONLY)),
            _ci(canon.false_flag_rate, bootstrap_interval(canon.flagged, canon.joint_frames)),
            _ci(canon.recall, bootstrap_interval(canon.hits, canon.injected))
            + f" (n={int(canon.injected.sum())})",
            _ci(mine.false_flag_rate, bootstrap_interval(mine.flagged, mine.joint_frames)),
            _ci(mine.recall, bootstrap_interval(mine.hits, mine.injected)),
        )
        per_joint[rig_takes.family] = (
            {r: canon.per_joint_flagged[r] / max(canon.per_joint_frames[r], 1)
             for r in canon.per_joint_flagged},
            {r: mine.per_joint_flagged[r] / max(mine.per_joint_frames[r], 1)
             for r in mine.per_joint_flagged},
        )  # fmt: skip
        if mine.spun.any():
            # The same held-back takes without those with a limb spin or flip (real retarget
            # errors the twist step reports): the rig map's worst joint there.
            kept = tuple(t for t in rig_takes.held_back if not find_limb_spins(t[1]))
            clean = count_takes(own, kept, seed, min_offset_deg)
            worst_role = max(
                clean.per_joint_flagged,
                key=lambda r: clean.per_joint_flagged[r] / max(clean.per_joint_frames[r], 1),
            )
            share = clean.per_joint_flagged[worst_role] / max(clean.per_joint_frames[worst_role], 1)
            unspun_notes.append(
                f"{rig_takes.family}: {int(mine.spun.sum())} held-back take(s) with a limb spin "
                f"or flip; on the other {len(clean.flagged)}, rig map false flags "
                f"{_pct(clean.false_flag_rate)} %, worst joint {worst_role} {_pct(share)} %"
            )
    console.print(table)
    for note in unspun_notes:
        console.print(note)
    joints = Table(title="false flags % per joint on held-back takes (canonical / rig map)")
    joints.add_column("role")
    for family in per_joint:
        joints.add_column(family)
    for role in (j.role for j in model.joints):
        joints.add_row(
            role,
            *(
                f"{_pct(c.get(role, float('nan')))} / {_pct(o.get(role, float('nan')))}"
                for c, o in per_joint.values()
            ),
        )
    console.print(joints)
    grouped: dict[str, list[tuple[str, Motion]]] = {}
    for name, motion in role_takes(corpus_dir):
        grouped.setdefault(rig_family(motion.skeleton), []).append((name, motion))
    groups = {family: tuple(takes) for family, takes in grouped.items()}
    for framed_once in (False, True) if leave_one_out else ():
        loro = leave_one_rig_out(groups, DEFAULT_BUILD, seed, min_offset_deg, framed_once)
        how = "framed once from all its clean takes" if framed_once else "each take framed alone"
        table = Table(title=f"leave one rig out: canonical map built without the rig ({how})")
        for column in (
            "left-out rig", "takes", "build takes", "false flags %",
            "false flags %, takes without spins (n)", "injected flagged %",
            "false flags % per joint (> 0)",
        ):  # fmt: skip
            table.add_column(column)
        for family, (left_model, counts) in loro.items():
            worst = sorted(counts.per_joint_flagged, key=lambda r: -counts.per_joint_flagged[r])
            flags = bootstrap_interval(counts.flagged, counts.joint_frames)
            table.add_row(
                family,
                str(len(counts.flagged)),
                str(len(left_model.takes)),
                _ci(counts.false_flag_rate, flags),
                _ci(
                    counts.unspun_false_flag_rate,
                    bootstrap_interval(
                        counts.flagged[~counts.spun], counts.joint_frames[~counts.spun]
                    ),
                )
                + f" ({int((~counts.spun).sum())})",
                _ci(counts.recall, bootstrap_interval(counts.hits, counts.injected))
                + f" (n={int(counts.injected.sum())})",
                ", ".join(
                    f"{r} {_pct(counts.per_joint_flagged[r] / counts.per_joint_frames[r])}"
                    for r in worst
                    if counts.per_joint_flagged[r]
                ),
            )
        rates = [c.false_flag_rate for _, c in loro.values()]
        unspun = [c.unspun_false_flag_rate for _, c in loro.values()]
        console.print(table)
        console.print(
            f"mean false flags over left-out rigs: {_pct(sum(rates) / len(rates))} %; on the "
            f"takes without a limb spin or flip (real retarget errors, reported by the twist "
            f"step): {_pct(sum(unspun) / len(unspun))} %"
        )
    scores = Table(title="canonical discriminators: held-out synthetic test accuracy")
    for column in ("role", "accuracy %", "precision %", "recall %", "hidden", "n test"):
        scores.add_column(column)
    for joint in model.joints:
        sc = joint.scores
        if sc is None:
            scores.add_row(joint.role, "—", "—", "—", "—", "—")
        else:
            scores.add_row(
                joint.role, _pct(sc.accuracy), _pct(sc.precision), _pct(sc.recall),
                str(sc.hidden_size), str(sc.n_test),
            )  # fmt: skip
    console.print(scores)
    for rig_takes in rigs:
        longest = max((m for _, m in rig_takes.held_back), key=lambda m: m.n_frames)
        speed = canonical_speed(model, longest)
        networks = all(j.network is not None for j in model.joints)
        by_network = canonical_speed(model, longest, 2, "network") if networks else math.nan
        console.print(
            f"speed {rig_takes.family} ({longest.skeleton.n_joints} joints): "
            f"{speed / 1e6:.2f} M joint-frames per CPU second (map check, canonical frames "
            f"included); network check (--network) {by_network / 1e6:.2f} M"
        )


def _bench_per_rig(
    corpus_dir: Path, rig: str | None, networks: bool, min_offset_deg: float, seed: int,
    shipped: bool,
) -> None:  # fmt: skip

    from dataclasses import replace

    from mocapqa.bench.limits import bench_rig, corpus_rigs
    from mocapqa.limits.build import DEFAULT_BUILD
    from mocapqa.limits.storage import default_model_paths, load_model

    models = {p.stem: load_model(p) for p in default_model_paths()} if shipped and networks else {}
    settings = DEFAULT_BUILD if networks else replace(DEFAULT_BUILD, discriminator=None)
    console.print(
        f"map: bin {settings.occupancy.bin_deg}°, dilation {settings.occupancy.dilation_bins} "
        f"bins, twist margin {settings.occupancy.tau_margin_deg}°, reference {settings.reference}"
    )
    summary = Table(title="limits per rig (held-back takes)")
    for column in (
        "rig", "build takes/frames", "held-back takes/frames", "false flags % (map)",
        "false flags % (net)", f"injected ≥{min_offset_deg:.0f}° flagged %", "lookup jf/s",
        "map check jf/s", "net check jf/s",
    ):  # fmt: skip
        summary.add_column(column)
    for rig_takes in corpus_rigs(corpus_dir, (rig,) if rig else None):
        model = models.get(rig_takes.family)
        if model is not None and model.takes != tuple(n for n, _ in rig_takes.build):
            model = None
        console.print(
            f"{rig_takes.family}: {'shipped model' if model else 'model built now'}, "
            f"{len(rig_takes.build)} build takes, {len(rig_takes.held_back)} held back"
        )
        _, figures = bench_rig(
            rig_takes, settings, seed=seed, min_offset_deg=min_offset_deg, model=model
        )
        table = Table(title=f"{figures.family}: per joint")
        for column in ("joint", "accuracy %", "precision %", "recall %", "hidden", "false flags %"):
            table.add_column(column)
        for j in figures.joints:
            table.add_row(
                j.name, _pct(j.accuracy), _pct(j.precision), _pct(j.recall), str(j.hidden_size),
                _pct(j.false_flag_rate),
            )  # fmt: skip
        console.print(table)
        summary.add_row(
            figures.family,
            f"{figures.n_build_takes}/{figures.n_build_frames}",
            f"{figures.n_held_back_takes}/{figures.n_held_back_frames}",
            _pct(figures.false_flag_rate),
            _pct(figures.network_false_flag_rate),
            f"{_pct(figures.injected_flag_rate)} (n={figures.n_injected})",
            f"{figures.lookup_joint_frames_per_s:.3g}",
            f"{figures.map_joint_frames_per_s:.3g}",
            f"{figures.network_joint_frames_per_s:.3g}",
        )
    console.print(summary)
