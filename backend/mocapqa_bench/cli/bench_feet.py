"""``mocapqa bench feet``: contacts against the force plates of the C3D gait trials (contact
speeds chosen leaving each trial out), threshold choice on the fit takes, then recall of
injected slides and penetrations and false skate flags on the held-back takes, and speed
and the foot lock on held-back takes with slides injected through the leg
(:mod:`mocapqa_bench.feet`, :mod:`mocapqa_bench.feet_plates`,
:mod:`mocapqa_bench.feet_cleanup`). ``--plates-only`` stops after the force plates,
``--cleanup-only`` runs only the foot lock's table (with the default parameters)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from mocapqa.cli.app import bench_app

if TYPE_CHECKING:
    from rich.console import Console
    from rich.table import Table

    from mocapqa.core.arrays import FloatArray

__all__ = ["bench_feet"]


def _share(pair: tuple[int, int]) -> str:
    found, tried = pair
    return f"{found}/{tried}" if tried else "–"


def _ms(errors: object, q: float) -> str:
    import numpy as np

    values = np.abs(np.asarray(errors, dtype=np.float64))
    return f"{np.percentile(values, q):.0f}" if values.size else "–"


def _plates_table(console: Console, root: Path) -> None:
    """The contact detector against the force plates, one row per C3D trial with plates."""
    import numpy as np
    from rich.table import Table

    from mocapqa.feet.plates import PLATE_THRESHOLD_N
    from mocapqa_bench.feet_plates import marker_params_by_leave_one_out, plate_trials

    with console.status("reading the force-plate trials"):
        trials = plate_trials(root)
        rows, chosen = marker_params_by_leave_one_out(trials)
    table = Table(
        title=f"Contacts against force plates (> {PLATE_THRESHOLD_N:g} N), each trial scored "
        "with the contact speeds chosen on the others",
        title_justify="left",
    )
    for column in (
        "trial",
        "fps",
        "strikes",
        "found",
        "right/judged",
        "P",
        "R",
        "onset ms",
        "offset ms",
        "speeds",
        "window s",
        "events s",
    ):
        table.add_column(column, justify="left" if column == "trial" else "right")  # fmt: skip
    pooled_on: list[FloatArray] = []
    pooled_off: list[FloatArray] = []
    skipped = []
    for row in rows:
        score, trial = row.score, row.trial
        if score is None or trial.points is None:
            plural = "s" if trial.plates != 1 else ""
            skipped.append(f"{trial.name} ({trial.plates} plate{plural}): {trial.note}")
            continue
        pooled_on.append(score.onset_ms)
        pooled_off.append(score.offset_ms)
        table.add_row(
            Path(trial.name).name, f"{trial.points.fps:g}",
            f"{score.plate_contacts}" + (f"+{score.unassigned}" if score.unassigned else ""),
            str(score.found), f"{score.right}/{score.judged}",
            f"{score.precision:.2f}", f"{score.recall:.2f}",
            f"{_ms(score.onset_ms, 50)} / {_ms(score.onset_ms, 90)}",
            f"{_ms(score.offset_ms, 50)} / {_ms(score.offset_ms, 90)}",
            f"{row.params.contact_speed:g} / {row.params.release_speed:g}",
            f"{row.params.speed_window_s:g}",
            f"{row.params.event_before_s:g} / {row.params.event_after_s:g}",
        )  # fmt: skip
    onsets = np.concatenate(pooled_on) if pooled_on else np.zeros(0)
    offsets = np.concatenate(pooled_off) if pooled_off else np.zeros(0)
    table.caption = (
        "strikes: plate contacts of one foot (+ those with no foot, not counted); right/judged:"
        " detected contacts standing on a plate that overlap a strike of their foot; onset and "
        "offset: |detected − plate| median / 90th percentile; speeds (leg/s), smoothing window "
        "and events: contact / release speed, speed_window_s and the window before / after an "
        "edge in which it moves to the heel's impact or the toe's push-off (event_before_s / "
        "event_after_s, 0 / 0: not moved), chosen on the other trials"
    )
    console.print(table)
    console.print(
        f"all trials: onset {_ms(onsets, 50)} / {_ms(onsets, 90)} ms, offset "
        f"{_ms(offsets, 50)} / {_ms(offsets, 90)} ms (median / 90th percentile); chosen on all "
        f"trials: contact_speed {chosen.contact_speed:g}, release_speed "
        f"{chosen.release_speed:g} leg/s, speed_window_s {chosen.speed_window_s:g}, "
        f"contact_height {chosen.contact_height:g}, release_height {chosen.release_height:g} "
        f"leg, event_before_s {chosen.event_before_s:g}, event_after_s "
        f"{chosen.event_after_s:g}"
    )
    for line in skipped:
        console.print(f"not scored: {line}")


def _cleanup_table(console: Console, root: Path, takes: list[Any], params: Any, seed: int) -> None:
    """The foot lock after ``feet fix --apply all`` on slides injected into held-back takes."""
    import numpy as np
    from rich.table import Table

    from mocapqa_bench.feet_cleanup import CLEANUP_SLIDES_CM, held_back_cleanup

    with console.status("locking feet on the held-back takes"):
        trials = held_back_cleanup(root, takes, params, seed)
    table = Table(
        title=f"Foot lock (feet fix --apply all) after slides of "
        f"{', '.join(f'{s:g}' for s in CLEANUP_SLIDES_CM)} cm injected through the leg, "
        f"held-back takes, seed {seed}",
        title_justify="left",
    )
    columns = (
        "family", "takes", "trials", "injected cm", "residual cm", "≤ 0.5 cm", "at joints cm",
        "clean cm", "hip/knee ° blends", "° elsewhere", "upper body", "clamped",
        "pop cm/s", "foot-frames/s",
    )  # fmt: skip
    for column in columns:
        table.add_column(column, justify="left" if column == "family" else "right")
    groups = sorted({t.family for t in trials})
    for family in [*groups, "all"]:
        rows = [t for t in trials if family in ("all", t.family)]
        if not rows:
            continue

        def values(name: str, group: list[Any] = rows) -> Any:
            return np.array([getattr(t, name) for t in group], dtype=np.float64)

        residual = values("fixed_cm")
        pop = {a: np.array([t.pop_cm_s[a] for t in rows]) for a in ("middle", "start")}
        locked = values("locked_frames").sum()
        table.add_row(
            family, str(len({t.take for t in rows})), str(len(rows)),
            f"{np.median(values('injected_cm')):.2f}",
            f"{np.median(residual):.2f} / {residual.max():.2f}",
            f"{np.mean(residual <= 0.5):.1%}",
            f"{np.median(values('fixed_joints_cm')):.2f} / {values('fixed_joints_cm').max():.2f}",
            f"{np.median(values('clean_cm')):.2f}",
            f"{values('hip_knee_deg_blends').max():.1f}",
            f"{values('hip_knee_deg_outside').max():.1f}",
            f"{int(values('upper_body_changed').max())}",
            f"{values('clamped_frames').sum() / locked:.1%}",
            f"{np.median(pop['middle']):.0f} ({np.median(pop['start']):.0f})",
            f"{locked / values('cpu_s').sum():,.0f}",
        )  # fmt: skip
    table.caption = (
        "injected / residual / clean: the check's travel of the contact (skate measure, no "
        "threshold), median (residual: median / max) on the injected take, after the lock, and "
        "on the clean take; at joints: the residual read at the joints (median / max, "
        "sole_pivot off; the lock holds the sole); hip/knee °: largest change of a hip or knee "
        "rotation in the blend frames around locked contacts, and anywhere else outside them; "
        "upper body: joints outside the legs whose world position changed; clamped: solved "
        "foot-frames whose ankle missed its target by more than 0.001 leg; pop: median over "
        "trials of the largest speed the lock adds to an ankle, anchor at the contact's "
        "middle (at its start); foot-frames/s: solved foot-frames per CPU second of the lock "
        "(forward kinematics, IK and the slide after, each take locked twice)"
    )
    console.print(table)


def _choice_table(choice: Any) -> Table:
    """The skate parameters tried on the fit takes, with their recall and false flags."""
    from rich.table import Table

    from mocapqa_bench.feet import CLEAN_FAMILIES, MAX_FLAGS_PER_MINUTE

    grid = Table(
        title=f"Choice on the fit takes (false flags ≤ {MAX_FLAGS_PER_MINUTE}/min on "
        f"{', '.join(CLEAN_FAMILIES)})",
        title_justify="left",
    )
    for column in (
        "plant_height", "plant_speed", "sole_depth", "slide_height", "skate_travel",
        "recall ≥ 2 cm", "flags/min",
    ):  # fmt: skip
        grid.add_column(column, justify="right")
    for height, speed, sole, slide, travel, recall, flags in choice.candidates:
        grid.add_row(
            f"{height:g}", f"{speed:g}", f"{sole:g}", f"{slide:g}", f"{travel:g}",
            f"{recall:.3f}", f"{flags:.2f}",
        )  # fmt: skip
    grid.caption = f"fit takes: {', '.join(choice.fit_takes)}"
    return grid


def _clean_table(root: Path, rows: list[Any]) -> Table:
    """Contacts and skate findings per minute per family and split, on the takes as they are."""
    from rich.table import Table

    from mocapqa_bench.feet import CLEAN_FAMILIES

    clean_table = Table(title=f"Clean takes ({root})", title_justify="left")
    for column in ("family", "split", "takes", "minutes", "contacts", "skate/min"):
        clean_table.add_column(column, justify="left" if column in ("family", "split") else "right")
    for row in rows:
        clean_table.add_row(
            row.family + (" (clean)" if row.family in CLEAN_FAMILIES else ""), row.split,
            str(row.takes), f"{row.minutes:.2f}", str(row.contacts),
            f"{row.skate_per_minute:.2f}",
        )  # fmt: skip
    clean_table.caption = "skate/min: skate findings per minute on the takes as they are"
    return clean_table


def _recall_table(rows: list[Any], seed: int) -> Table:
    """The injected slides and sinks found per family and split."""
    from rich.table import Table

    from mocapqa_bench.feet import DEPTHS_CM, SLIDES_CM

    recall_table = Table(title=f"Injected errors found, seed {seed}", title_justify="left")
    recall_table.add_column("injected")
    for row in rows:
        recall_table.add_column(f"{row.family}\n{row.split}", justify="right")
    for size in SLIDES_CM:
        recall_table.add_row(f"slide {size:g} cm", *(_share(r.slide_recall[size]) for r in rows))
    for size in DEPTHS_CM:
        recall_table.add_row(
            f"sink {size:g} cm", *(_share(r.penetration_recall[size]) for r in rows)
        )
    recall_table.add_row("slide error cm", *(f"{r.slide_error_cm:.2f}" for r in rows))
    recall_table.caption = (
        "found/tried; slides over the contact's middle (at most 1 s), sinks over its middle "
        "half (at most 0.5 s) where the foot stands on the floor; slide error: median "
        "|measured − injected| of the slides found"
    )
    return recall_table


@bench_app.command("feet")
def bench_feet(
    data: Annotated[
        Path | None,
        typer.Option(help="Corpus folder (default: $MOCAPQA_CORPUS_DIR or ../shared/data)."),
    ] = None,
    seed: Annotated[int, typer.Option(help="Seed of the slide directions.")] = 0,
    choose: Annotated[
        bool,
        typer.Option(
            "--choose/--defaults",
            help="Choose the skate parameters on the fit takes (default), or use FeetParams' "
            "defaults as they are.",
        ),
    ] = True,
    plates_only: Annotated[
        bool, typer.Option("--plates-only", help="Only the force-plate contacts (C3D trials).")
    ] = False,
    cleanup_only: Annotated[
        bool,
        typer.Option("--cleanup-only", help="Only the foot lock's table (default parameters)."),
    ] = False,
) -> None:
    """Contacts against force plates; injected slide and penetration recall, false skate flags
    per minute, foot-frames/s."""
    from rich.console import Console

    from mocapqa.corpus import require_corpus
    from mocapqa.feet.params import FeetParams
    from mocapqa_bench.feet import bench_takes, choose_params, family_figures, feet_speed

    console = Console()
    root = require_corpus(data)
    if not cleanup_only:
        _plates_table(console, root)
    if plates_only:
        return
    with console.status("reading the corpus"):
        takes = bench_takes(root)
    params = FeetParams()
    if cleanup_only:
        _cleanup_table(console, root, takes, params, seed)
        return
    if choose:
        with console.status("choosing the skate parameters on the fit takes"):
            choice = choose_params(takes, seed)
        params = choice.params
        console.print(_choice_table(choice))
    console.print(
        f"parameters: skate_travel={params.skate_travel:g}, plant_height="
        f"{params.plant_height:g}, plant_speed={params.plant_speed:g}, sole_depth="
        f"{params.sole_depth:g}, slide_height={params.slide_height:g} (leg lengths), "
        f"slide_speed={params.slide_speed:g} leg/s, "
        f"skate_window_s={params.skate_window_s:g}, penetration_depth="
        f"{params.penetration_depth:g}"
    )
    with console.status("injecting slides and penetrations"):
        rows = family_figures(takes, params, seed)
    console.print(_clean_table(root, rows))
    console.print(_recall_table(rows, seed))
    _cleanup_table(console, root, takes, params, seed)
    with console.status("timing"):
        rate = feet_speed(takes, params)
        long_rate = feet_speed(takes, params, concatenate=True)
    console.print(
        f"speed: {rate:,.0f} foot-frames per CPU second over the {len(takes)} takes one by one; "
        f"{long_rate:,.0f} on one long take made of them all"
    )
