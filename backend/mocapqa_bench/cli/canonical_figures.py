"""The canonical-model figures of ``mocapqa bench limits``: per rig against the rig's own map,
leave-one-rig-out, the discriminators' scores and the speed, with bootstrap intervals."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.table import Table

if TYPE_CHECKING:
    from mocapqa.limits.build import BuildParams
    from mocapqa.limits.model import LimitsModel
    from mocapqa_bench.limits import RigTakes

__all__ = ["ci", "pct", "print_canonical"]

console = Console(highlight=False)


def pct(value: float) -> str:
    """A share as a percentage to two decimals ("—" for NaN)."""
    return "—" if math.isnan(value) else f"{100 * value:.2f}"


def ci(value: float, interval: tuple[float, float]) -> str:
    """A share and its interval as percentages."""
    return f"{pct(value)} [{pct(interval[0])}–{pct(interval[1])}]"


def _map_only() -> BuildParams:
    """The default build without the discriminator networks."""
    from dataclasses import replace

    from mocapqa.limits.build import DEFAULT_BUILD

    return replace(DEFAULT_BUILD, discriminator=None)


def print_canonical(
    corpus_dir: Path, shipped: bool, seed: int, min_offset_deg: float,
    model_path: Path | None = None, leave_one_out: bool = True,
) -> None:  # fmt: skip
    """The canonical model on each rig's held-back takes against the rig's own map, left out
    (``leave_one_out``), its discriminators' scores and its speed."""
    from mocapqa_bench.limits import corpus_rigs

    model, names = _canonical_model(corpus_dir, shipped, model_path)
    occ = model.occupancy_params
    console.print(
        f"map: bin {occ.bin_deg}°, dilation {occ.dilation_bins}, twist margin "
        f"{occ.tau_margin_deg}°, interpolated {occ.interpolate}; {len(names)} build takes; "
        f"injected offsets {min_offset_deg:.0f}–180°, seed {seed}; [95 % bootstrap over takes]"
    )
    rigs = corpus_rigs(corpus_dir)
    _held_back_tables(model, rigs, seed, min_offset_deg)
    if leave_one_out:
        _loro_tables(corpus_dir, seed, min_offset_deg)
    _scores_table(model)
    _canonical_speeds(model, rigs)


def _canonical_model(
    corpus_dir: Path, shipped: bool, model_path: Path | None
) -> tuple[LimitsModel, tuple[str, ...]]:
    """The canonical model on the build takes of ``corpus_dir`` (and their names):
    ``model_path``, else the shipped one if ``shipped`` and it has the same build takes, else
    one built now (map only).

    Raises
    ------
    InputError
        If ``model_path`` is not a canonical model of those build takes.
    """
    from mocapqa.errors import InputError
    from mocapqa.limits.build import build_canonical_model
    from mocapqa.limits.storage import default_model_paths, load_model
    from mocapqa_bench.limits import canonical_takes
    from mocapqa_bench.limits_canonical import EVALUATION_ONLY

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
    if model is None:
        console.print("canonical model: built now (map only)")
        built = build_canonical_model([m for _, m in build_takes], list(names), _map_only())
        return built, names
    if model_path is not None:
        console.print(f"canonical model: {model_path} (same build takes)")
    else:
        console.print("canonical model: the shipped one (same build takes)")
    return model, names


def _joint_shares(counts: Any) -> dict[str, float]:
    """Share of flagged frames per role of a count."""
    return {
        r: counts.per_joint_flagged[r] / max(counts.per_joint_frames[r], 1)
        for r in counts.per_joint_flagged
    }


def _held_back_tables(
    model: LimitsModel, rigs: list[RigTakes], seed: int, min_offset_deg: float
) -> None:
    """Per rig: the canonical model against the rig's own map on its held-back takes, in all
    and per joint."""
    from mocapqa.limits.build import build_model
    from mocapqa_bench.limits_canonical import EVALUATION_ONLY, bootstrap_interval, count_takes

    map_only = _map_only()

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
            ci(canon.false_flag_rate, bootstrap_interval(canon.flagged, canon.joint_frames)),
            ci(canon.recall, bootstrap_interval(canon.hits, canon.injected))
            + f" (n={int(canon.injected.sum())})",
            ci(mine.false_flag_rate, bootstrap_interval(mine.flagged, mine.joint_frames)),
            ci(mine.recall, bootstrap_interval(mine.hits, mine.injected)),
        )
        per_joint[rig_takes.family] = (_joint_shares(canon), _joint_shares(mine))
        if mine.spun.any():
            unspun_notes.append(_unspun_note(own, rig_takes, mine, seed, min_offset_deg))
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
                f"{pct(c.get(role, float('nan')))} / {pct(o.get(role, float('nan')))}"
                for c, o in per_joint.values()
            ),
        )
    console.print(joints)


def _unspun_note(
    own: LimitsModel, rig_takes: RigTakes, mine: Any, seed: int, min_offset_deg: float
) -> str:
    """The same held-back takes without those with a limb spin or flip (real retarget errors
    the twist step reports): the rig map's worst joint there (``mine``: the rig map's count
    on every held-back take)."""
    from mocapqa.twist.spin import find_limb_spins
    from mocapqa_bench.limits_canonical import count_takes

    kept = tuple(t for t in rig_takes.held_back if not find_limb_spins(t[1]))
    clean = count_takes(own, kept, seed, min_offset_deg)
    worst_role = max(
        clean.per_joint_flagged,
        key=lambda r: clean.per_joint_flagged[r] / max(clean.per_joint_frames[r], 1),
    )
    share = clean.per_joint_flagged[worst_role] / max(clean.per_joint_frames[worst_role], 1)
    return (
        f"{rig_takes.family}: {int(mine.spun.sum())} held-back take(s) with a limb spin "
        f"or flip; on the other {len(clean.flagged)}, rig map false flags "
        f"{pct(clean.false_flag_rate)} %, worst joint {worst_role} {pct(share)} %"
    )


def _loro_tables(corpus_dir: Path, seed: int, min_offset_deg: float) -> None:
    """Leave one rig out: each rig checked by a canonical map built without it, with each
    take framed alone and framed once from all its clean takes."""
    from mocapqa.core.motion import Motion
    from mocapqa.limits.build import DEFAULT_BUILD
    from mocapqa.limits.rig import rig_family
    from mocapqa_bench.limits import role_takes
    from mocapqa_bench.limits_canonical import leave_one_rig_out

    grouped: dict[str, list[tuple[str, Motion]]] = {}
    for name, motion in role_takes(corpus_dir):
        grouped.setdefault(rig_family(motion.skeleton), []).append((name, motion))
    groups = {family: tuple(takes) for family, takes in grouped.items()}
    for framed_once in (False, True):
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
            table.add_row(family, *_loro_cells(left_model, counts))
        rates = [c.false_flag_rate for _, c in loro.values()]
        unspun = [c.unspun_false_flag_rate for _, c in loro.values()]
        console.print(table)
        console.print(
            f"mean false flags over left-out rigs: {pct(sum(rates) / len(rates))} %; on the "
            f"takes without a limb spin or flip (real retarget errors, reported by the twist "
            f"step): {pct(sum(unspun) / len(unspun))} %"
        )


def _loro_cells(left_model: LimitsModel, counts: Any) -> tuple[str, ...]:
    """The cells after the rig's name of its leave-one-rig-out row."""
    from mocapqa_bench.limits_canonical import bootstrap_interval

    worst = sorted(counts.per_joint_flagged, key=lambda r: -counts.per_joint_flagged[r])
    flags = bootstrap_interval(counts.flagged, counts.joint_frames)
    unspun = bootstrap_interval(counts.flagged[~counts.spun], counts.joint_frames[~counts.spun])
    return (
        str(len(counts.flagged)),
        str(len(left_model.takes)),
        ci(counts.false_flag_rate, flags),
        ci(counts.unspun_false_flag_rate, unspun) + f" ({int((~counts.spun).sum())})",
        ci(counts.recall, bootstrap_interval(counts.hits, counts.injected))
        + f" (n={int(counts.injected.sum())})",
        ", ".join(
            f"{r} {pct(counts.per_joint_flagged[r] / counts.per_joint_frames[r])}"
            for r in worst
            if counts.per_joint_flagged[r]
        ),
    )


def _scores_table(model: LimitsModel) -> None:
    """The canonical discriminators' accuracy on their held-out synthetic test split."""
    scores = Table(title="canonical discriminators: held-out synthetic test accuracy")
    for column in ("role", "accuracy %", "precision %", "recall %", "hidden", "n test"):
        scores.add_column(column)
    for joint in model.joints:
        sc = joint.scores
        if sc is None:
            scores.add_row(joint.role, "—", "—", "—", "—", "—")
        else:
            scores.add_row(
                joint.role, pct(sc.accuracy), pct(sc.precision), pct(sc.recall),
                str(sc.hidden_size), str(sc.n_test),
            )  # fmt: skip
    console.print(scores)


def _canonical_speeds(model: LimitsModel, rigs: list[RigTakes]) -> None:
    """Check speed of the canonical model on each rig's longest held-back take."""
    from mocapqa_bench.limits_canonical import canonical_speed

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
