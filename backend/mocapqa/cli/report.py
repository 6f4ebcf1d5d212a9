"""``mocapqa report``: a self-contained HTML (optionally PDF) QA report of one take.

The take is analysed with the pipeline (or a stored run's folder is read with ``--run``), the
contact sheet is rendered on the one render thread, and
:func:`mocapqa.report.html.report_from_analysis` writes the page. The helpers here are
shared with ``mocapqa render``.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import typer
from rich.console import Console
from rich.progress import Progress

from mocapqa.cli.app import app
from mocapqa.cli.outputs import check_outputs, require_suffix, take_input
from mocapqa.cli.reading import read_input
from mocapqa.cli.roles import (
    MappingOption,
    RootTranslationOption,
    load_mapping,
    warn_missing,
)
from mocapqa.errors import InputError, MocapQAError, NotFoundError

if TYPE_CHECKING:
    from mocapqa.render.scene import SkeletonTrack
    from mocapqa.render.service import RenderService
    from mocapqa.render.sheet import SheetTile

__all__ = [
    "CHROMIUM",
    "TakeRun",
    "analyze_take",
    "build_take_report",
    "load_run",
    "print_pdf",
    "report",
    "sheet_tiles",
    "take_facts",
]

# Debian's Chromium, used for print-to-PDF.
CHROMIUM = Path("/usr/bin/chromium")
MAX_TILES = 8

console = Console(highlight=False)


@dataclass(frozen=True)
class TakeRun:
    """One analysed take, ready to draw and report.

    Parameters
    ----------
    analysis : dict
        The pipeline's report JSON (summary, steps, findings, series, options).
    raw, corrected : SkeletonTrack
        Points as recorded and after correction (twist refinement or filtering).
    """

    analysis: dict[str, Any]
    raw: SkeletonTrack
    corrected: SkeletonTrack


def take_facts(path: Path) -> dict[str, Any]:
    """Name, size and sha256 of a take file (or of an OpenPose folder's name)."""
    facts: dict[str, Any] = {"name": path.name, "file": str(path)}
    if path.is_file():
        data = path.read_bytes()
        facts["bytes"] = len(data)
        facts["sha256"] = hashlib.sha256(data).hexdigest()
    return facts


def analyze_take(
    path: Path,
    options: dict[str, Any] | None = None,
    progress: Callable[[int, str], None] | None = None,
    root_translation: Literal["auto", "add", "replace"] = "auto",
) -> TakeRun:
    """Read and analyse a take with the pipeline's defaults (or ``options``).

    ``root_translation`` says how a BVH root's position is read (see
    :mod:`mocapqa.io.bvh_root`); the report's summary says which reading was used and why.
    """
    from mocapqa.core.keypoints import KeypointSequence
    from mocapqa.core.motion import Motion
    from mocapqa.io.bvh_root import explain_root_translation
    from mocapqa.io.formats import require_frames
    from mocapqa.jobs.rendered import tracks_of
    from mocapqa.pipeline.analyze import analyze
    from mocapqa.pipeline.options import AnalysisOptions

    take = read_input(path, root_translation=root_translation)
    require_frames(take, path)
    result = analyze(take, AnalysisOptions.from_json(options), progress)
    if isinstance(take, Motion):
        reason = explain_root_translation(take, root_translation)
        result.report["summary"]["root_translation_reason"] = reason
    raw_positions = result.raw_points
    corrected_positions = result.corrected_points
    if isinstance(take, KeypointSequence):
        # Keep missing keypoints missing (the pipeline zero-fills them for its 3D view).
        raw_positions = take.positions
        if result.filtered_keypoints is not None:
            corrected_positions = result.filtered_keypoints.positions
    raw, corrected = tracks_of(result.report, raw_positions, corrected_positions)
    return TakeRun(result.report, raw, corrected)


def load_run(folder: Path) -> TakeRun:
    """Read a stored run's folder (its report and points) without re-analysing."""
    from mocapqa.jobs.rendered import run_tracks
    from mocapqa.jobs.stored_run import read_run

    stored = read_run(folder)
    raw, corrected = run_tracks(stored)
    return TakeRun(stored.report, raw, corrected)


def sheet_tiles(run: TakeRun, max_tiles: int = MAX_TILES) -> list[SheetTile]:
    """Contact-sheet tiles for a run's findings: twist intervals first, then the largest
    limit violations, at most ``max_tiles``."""
    from mocapqa.render.sheet import tiles_from_intervals
    from mocapqa.report.findings import sheet_findings

    chosen = sheet_findings(list(run.analysis.get("findings", [])), max_tiles)
    return tiles_from_intervals(chosen, run.raw, run.corrected)


def build_take_report(
    path: Path,
    service: RenderService,
    run_folder: Path | None = None,
    options: dict[str, Any] | None = None,
    progress: Callable[[int, str], None] | None = None,
    root_translation: Literal["auto", "add", "replace"] = "auto",
) -> str:
    """Analyse (or load) a take, render its contact sheet and return the report's HTML."""
    from mocapqa.report.html import report_from_analysis

    step = progress or (lambda percent, text: None)
    if run_folder is not None:
        run = load_run(run_folder)
    else:
        run = analyze_take(path, options, progress, root_translation)
    warn_missing(run.analysis.get("summary", {}).get("missing_roles") or [])
    tiles = sheet_tiles(run)
    sheet: bytes | None = None
    unavailable: dict[str, str] = {}
    if tiles:
        step(90, f"contact sheet ({len(tiles)} tiles)")
        try:
            sheet = service.contact_sheet(run.raw, tiles, run.corrected)
        except MocapQAError as e:
            unavailable["contact_sheet"] = f"rendering unavailable: {e}"
    step(97, "writing the report")
    facts = take_facts(path)
    if run_folder is not None:
        facts["run"] = str(run_folder)
    settings = {
        "options": run.analysis.get("options", {}),
        "command": "mocapqa report "
        + str(path)
        + (f" --run {run_folder}" if run_folder is not None else ""),
        "analysis_version": run.analysis.get("version"),
        "up_axis": run.raw.up_axis,
    }
    return report_from_analysis(
        run.analysis,
        facts,
        contact_sheet_png=sheet,
        settings=settings,
        unavailable=unavailable,
    )


def print_pdf(html_path: Path, pdf_path: Path, timeout_s: float = 120.0) -> str | None:
    """Print an HTML file to PDF with Debian's Chromium; returns why not, or None on success."""
    if not CHROMIUM.is_file():
        return f"no PDF: {CHROMIUM} is not installed (Debian package chromium)"
    with tempfile.TemporaryDirectory() as profile:
        command = [
            str(CHROMIUM),
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--disable-background-networking",
            "--no-first-run",
            f"--user-data-dir={profile}",
            "--no-pdf-header-footer",
            "--virtual-time-budget=10000",
            f"--print-to-pdf={pdf_path}",
            html_path.resolve().as_uri(),
        ]
        try:
            done = subprocess.run(command, capture_output=True, timeout=timeout_s, check=False)
        except (OSError, subprocess.TimeoutExpired) as e:
            return f"no PDF: Chromium did not finish ({e})"
    if done.returncode != 0 or not pdf_path.is_file():
        tail = done.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["no output"]
        return f"no PDF: Chromium exited {done.returncode} ({tail[0]})"
    return None


@app.command()
def report(
    input_path: Annotated[Path, typer.Argument(metavar="IN", help="Take (BVH or keypoints).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="HTML file to write.")] = Path(
        "report.html"
    ),
    run: Annotated[
        Path | None,
        typer.Option(help="A stored run's folder (report.json, points.npz) to report on."),
    ] = None,
    options: Annotated[
        Path | None, typer.Option(help="JSON file of analysis options (checks, methods).")
    ] = None,
    pdf: Annotated[
        Path | None, typer.Option(help="Also print the report to this PDF (needs Chromium).")
    ] = None,
    mapping: MappingOption = None,
    root_translation: RootTranslationOption = "auto",
) -> None:
    """Write a self-contained HTML QA report: summary, findings, timelines, contact sheet."""
    from mocapqa.io.atomic import write_bytes, write_text
    from mocapqa.jobs.run_folder import RunFolder
    from mocapqa.render.service import RenderService

    if not input_path.exists():
        raise NotFoundError(f"Expected an existing take file, got {input_path}")
    require_suffix("-o", output, (".html", ".htm"), "an HTML report")
    if pdf is not None:
        require_suffix("--pdf", pdf, (".pdf",), "a PDF report")
    stored = [RunFolder(run).report, RunFolder(run).points] if run is not None else []
    check_outputs({"-o": output, "--pdf": pdf}, [take_input(input_path), options, mapping, *stored])
    option_values = None
    if options is not None:
        try:
            option_values = json.loads(options.read_text(encoding="utf-8"))
        except (OSError, ValueError) as e:
            raise InputError(f"{options}: Expected a JSON object of options, got {e}") from e
    roles = load_mapping(mapping)
    if roles is not None:
        if run is not None:
            raise InputError("Expected --mapping only when analysing, got --run too")
        option_values = {**(option_values or {}), "mapping": roles}
    with Progress(console=console, transient=True) as bar, RenderService() as service:
        task = bar.add_task("analysing", total=100)

        def progress(percent: int, text: str) -> None:
            bar.update(task, completed=percent, description=text)

        html = build_take_report(
            input_path, service, run, option_values, progress, root_translation
        )
    write_text(output, html)
    console.print(f"report → {output} ({len(html) / 1e6:.1f} MB)")
    if pdf is not None:
        # Chromium needs the HTML as a file; a copy keeps the user's output untouched. It
        # prints to the scratch folder, and a printed PDF replaces the output whole.
        with tempfile.TemporaryDirectory() as folder:
            page = Path(folder) / "report.html"
            shutil.copyfile(output, page)
            printed = Path(folder) / "report.pdf"
            reason = print_pdf(page, printed)
            if reason is None:
                write_bytes(pdf, printed.read_bytes())
        console.print(reason if reason else f"PDF → {pdf}")
