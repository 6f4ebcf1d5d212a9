"""Self-contained HTML QA reports: one file that opens offline in any browser.

Conventions
-----------
* Plotly's JavaScript is inlined once from the installed wheel; images are embedded as base64
  ``data:`` URIs; a Content-Security-Policy forbids every network fetch, so the report shows
  the same thing on a machine with no network as on the one that made it.
* Sections: take summary, findings table, twist timeline, limits timeline, filter weights,
  contact sheet, settings and software versions. A section whose input is missing says why
  (``unavailable``) instead of disappearing, so a reader can tell "not run" from "nothing
  found".
* Inputs are plain JSON-ready dicts (the analyses' ``to_json()``) and PNG bytes; this module
  neither reads files nor renders images.
"""

from __future__ import annotations

import base64
import html
import json
import platform
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from importlib import metadata
from typing import Any

from mocapqa import __version__
from mocapqa.report.figures import (
    filter_weights_figure,
    limits_timeline_figure,
    twist_timeline_figure,
)
from mocapqa.report.findings import limit_findings, normalise_findings, twist_findings

__all__ = ["SECTIONS", "build_report", "report_from_analysis", "software_versions"]

# Sections that can be marked unavailable, with a reason.
SECTIONS = ("twist", "limits", "filters", "contact_sheet")

_CSS = """
body { font-family: system-ui, sans-serif; margin: 0 auto; max-width: 1200px; padding: 1rem 2rem;
       color: #1d2330; }
h1 { font-size: 1.6rem; margin-bottom: .2rem; }
h2 { font-size: 1.2rem; border-bottom: 1px solid #d0d4da; padding-bottom: .2rem; margin-top: 2rem; }
table { border-collapse: collapse; font-size: .9rem; }
th, td { border: 1px solid #d0d4da; padding: .25rem .6rem; text-align: left; }
th { background: #f2f4f7; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.muted { color: #6b7380; }
.unavailable { background: #fff6e5; border-left: 4px solid #f0a020; padding: .5rem .8rem; }
img.sheet { max-width: 100%; border: 1px solid #d0d4da; }
pre { background: #f5f6f8; padding: .6rem; overflow-x: auto; font-size: .85rem; }
"""

_CSP = (
    "default-src 'none'; script-src 'unsafe-inline' 'unsafe-eval'; "
    "style-src 'unsafe-inline'; img-src data:; font-src data:"
)


def software_versions() -> dict[str, str]:
    """Versions of mocapqa, Python and the libraries that shape the results."""
    versions = {"mocapqa": __version__, "python": platform.python_version()}
    for package in ("numpy", "scipy", "plotly", "pyvista", "vtk"):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = "not installed"
    return versions


def _plotly_js() -> str:
    from plotly.offline import get_plotlyjs

    return str(get_plotlyjs())


def _figure_html(fig: Any, div_id: str) -> str:
    import plotly.io as pio

    return str(
        pio.to_html(
            fig,
            full_html=False,
            include_plotlyjs=False,
            div_id=div_id,
            config={"displaylogo": False, "responsive": True},
        )
    )


def _esc(value: Any) -> str:
    return html.escape(str(value))


def _unavailable(reason: str) -> str:
    return f'<p class="unavailable">{_esc(reason)}</p>'


def _key_value_table(values: Mapping[str, Any]) -> str:
    rows = "".join(f"<tr><th>{_esc(k)}</th><td>{_esc(v)}</td></tr>" for k, v in values.items())
    return f"<table>{rows}</table>"


def _findings_table(findings: Sequence[Mapping[str, Any]], fps: float | None) -> str:
    if not findings:
        return '<p class="muted">No flagged intervals.</p>'
    head = (
        "<tr><th>#</th><th>kind</th><th>joint</th><th>frames</th><th>time (s)</th>"
        "<th>offset / spin / violation (deg)</th><th>confidence</th><th>read-out</th></tr>"
    )
    rows = []
    for k, f in enumerate(findings, start=1):
        start, end = int(f["start_frame"]), int(f["end_frame"])
        time_s = f"{start / fps:.2f}–{(end + 1) / fps:.2f}" if fps else ""
        if f.get("offset_deg") is not None:
            value_text = f"{float(f['offset_deg']):+.1f}"
        elif f.get("violation_deg") is not None:
            value_text = f"{float(f['violation_deg']):.1f}"
        else:
            value_text = ""
        confidence = f.get("confidence")
        confidence_text = "" if confidence is None else f"{float(confidence):.2f}"
        rows.append(
            f"<tr><td class=num>{k}</td><td>{_esc(f['kind'])}</td><td>{_esc(f['joint'])}</td>"
            f"<td class=num>{start}–{end}</td><td class=num>{time_s}</td>"
            f"<td class=num>{value_text}</td><td class=num>{confidence_text}</td>"
            f"<td>{_esc(f.get('readout', ''))}</td></tr>"
        )
    return f"<table>{head}{''.join(rows)}</table>"


def _png_tag(png: bytes, alt: str, css_class: str = "sheet") -> str:
    data = base64.b64encode(png).decode("ascii")
    return f'<img class="{css_class}" alt="{_esc(alt)}" src="data:image/png;base64,{data}">'


def build_report(
    take: Mapping[str, Any],
    *,
    twist: Mapping[str, Any] | None = None,
    limits: Mapping[str, Any] | None = None,
    filters: Mapping[str, Any] | None = None,
    findings: Sequence[Mapping[str, Any]] | None = None,
    filter_frames: Sequence[int] = (),
    contact_sheet_png: bytes | None = None,
    images: Sequence[tuple[str, bytes]] = (),
    settings: Mapping[str, Any] | None = None,
    software: Mapping[str, str] | None = None,
    unavailable: Mapping[str, str] | None = None,
    title: str | None = None,
) -> str:
    """Build a self-contained HTML report of one take.

    Parameters
    ----------
    take : mapping
        Take summary shown as a table (e.g. name, format, frames, fps, joints, sha256).
        ``fps`` is used for the time column of the findings.
    twist : mapping, optional
        ``TwistAnalysis.to_json()``.
    limits : mapping, optional
        ``LimitsReport.to_json()`` or the pipeline's limits series.
    filters : mapping, optional
        ``KeypointFilterResult.to_json()`` or the pipeline's filter series (blend weights).
    findings : sequence of mapping, optional
        The pipeline's findings; derived from ``twist`` and ``limits`` when omitted.
    filter_frames : sequence of int
        Frame numbers of the pipeline's filter series.
    contact_sheet_png : bytes, optional
        PNG of the contact sheet.
    images : sequence of (caption, PNG bytes)
        Further images, shown after the contact sheet.
    settings : mapping, optional
        Options the analyses ran with (JSON-ready), shown so the run can be repeated.
    software : mapping, optional
        Package versions; :func:`software_versions` when omitted.
    unavailable : mapping, optional
        Section name (one of :data:`SECTIONS`) → why it is missing.
    title : str, optional
        Page title; defaults to the take's name.

    Returns
    -------
    str
        The HTML document.
    """
    reasons = dict(unavailable or {})
    fps = take.get("fps")
    fps_value = float(fps) if isinstance(fps, (int, float)) and fps > 0 else None
    twists, spins, limit_runs = _split_findings(findings, twist, limits)
    name = title or str(take.get("name", "take"))
    parts = _head(name)
    parts.append('<h2 id="summary">Take summary</h2>')
    parts.append(_key_value_table(take))
    parts += _findings_section(twist, limits, reasons, [*twists, *spins, *limit_runs], fps_value)
    parts += _timeline_sections(
        {"twist": twist, "limits": limits, "filters": filters},
        reasons,
        twists,
        limit_runs,
        filter_frames,
    )
    parts += _images_section(contact_sheet_png, images, reasons)
    parts += _settings_section(settings, software)
    parts.append("</body></html>")
    return "\n".join(parts)


def _split_findings(
    findings: Sequence[Mapping[str, Any]] | None,
    twist: Mapping[str, Any] | None,
    limits: Mapping[str, Any] | None,
) -> tuple[list[dict[str, Any]], list[dict[str, Any]], list[dict[str, Any]]]:
    """The twist intervals, limb spins and other findings (limits, markers, feet) of a report:
    the pipeline's ``findings`` when given, else those of ``twist`` and ``limits``."""
    if findings is None:
        return twist_findings(twist), [], limit_findings(limits)
    given = normalise_findings([dict(f) for f in findings])
    twists = [f for f in given if f["kind"] == "twist"]
    spins = [f for f in given if f["kind"] == "spin"]
    others = [f for f in given if f["kind"] not in ("twist", "spin")]
    return twists, spins, others


def _head(name: str) -> list[str]:
    """The document's head (styles, policy, Plotly) and its title lines."""
    created = datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
    return [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f'<meta http-equiv="Content-Security-Policy" content="{_CSP}">',
        f"<title>mocapqa report · {_esc(name)}</title>",
        f"<style>{_CSS}</style>",
        f"<script>{_plotly_js()}</script>",
        "</head><body>",
        f"<h1>QA report · {_esc(name)}</h1>",
        f'<p class="muted">Generated {created} by mocapqa {_esc(__version__)}.</p>',
    ]


def _findings_section(
    twist: Mapping[str, Any] | None,
    limits: Mapping[str, Any] | None,
    reasons: Mapping[str, str],
    findings: list[dict[str, Any]],
    fps: float | None,
) -> list[str]:
    """The findings table, in frame order, after why the twist or limits check is missing."""
    parts = ['<h2 id="findings">Findings</h2>']
    missing = [s for s in ("twist", "limits") if (twist if s == "twist" else limits) is None]
    if missing:
        parts.append(_unavailable("; ".join(f"{s}: {reasons.get(s, 'not run')}" for s in missing)))
    # In frame order, as the take view lists them ungrouped.
    listed = sorted(findings, key=lambda f: (f["start_frame"], f["kind"]))
    parts.append(_findings_table(listed, fps))
    return parts


_TIMELINES = (
    ("twist", "twist-timeline", "Twist timeline"),
    ("limits", "limits-timeline", "Limits timeline"),
    ("filters", "filter-weights", "Filter weights"),
)
"""The plotted sections: key of their series, the figure's div id, heading."""


def _timeline_sections(
    series: Mapping[str, Mapping[str, Any] | None],
    reasons: Mapping[str, str],
    twists: list[dict[str, Any]],
    limit_runs: list[dict[str, Any]],
    filter_frames: Sequence[int],
) -> list[str]:
    """The twist timeline, limits timeline and filter weights sections (each its figure, or
    why it is missing)."""
    parts = []
    for key, div_id, heading in _TIMELINES:
        data = series[key]
        parts.append(f'<h2 id="{div_id}-section">{heading}</h2>')
        if data is None:
            parts.append(_unavailable(reasons.get(key, f"The {key} analysis was not run.")))
            continue
        if key == "twist":
            fig = twist_timeline_figure(data, twists)
        elif key == "limits":
            fig = limits_timeline_figure(data, limit_runs)
        else:
            fig = filter_weights_figure(data, filter_frames)
        if fig is None:
            parts.append('<p class="muted">Nothing to plot: the analysis returned no series.</p>')
        else:
            parts.append(_figure_html(fig, div_id))
    return parts


def _images_section(
    contact_sheet_png: bytes | None, images: Sequence[tuple[str, bytes]], reasons: Mapping[str, str]
) -> list[str]:
    """The contact sheet (or why there is none), then the further images with captions."""
    parts = ['<h2 id="contact-sheet">Contact sheet</h2>']
    if contact_sheet_png is not None:
        parts.append(_png_tag(contact_sheet_png, "contact sheet of the flagged intervals"))
    else:
        parts.append(
            _unavailable(reasons.get("contact_sheet", "No contact sheet: nothing was flagged."))
        )
    for caption, png in images:
        parts.append(
            f"<figure>{_png_tag(png, caption)}<figcaption>{_esc(caption)}</figcaption></figure>"
        )
    return parts


def _settings_section(
    settings: Mapping[str, Any] | None, software: Mapping[str, str] | None
) -> list[str]:
    """The options the analyses ran with and the software versions."""
    return [
        '<h2 id="settings">Settings and software</h2>',
        "<pre>"
        + _esc(json.dumps(dict(settings or {}), indent=2, sort_keys=True, default=str))
        + "</pre>",
        _key_value_table(dict(software or software_versions())),
    ]


def report_from_analysis(
    analysis: Mapping[str, Any],
    take: Mapping[str, Any],
    *,
    contact_sheet_png: bytes | None = None,
    images: Sequence[tuple[str, bytes]] = (),
    settings: Mapping[str, Any] | None = None,
    unavailable: Mapping[str, str] | None = None,
) -> str:
    """Build the report from a pipeline run's JSON (``AnalysisResult.report``).

    Parameters
    ----------
    analysis : mapping
        The run's report: ``summary``, ``steps``, ``findings``, ``series``, ``options``.
    take : mapping
        Take facts to show first (name, file, sha256...); the run's summary is added.
    contact_sheet_png, images, settings, unavailable
        As in :func:`build_report`; ``settings`` defaults to the run's options, and each step
        that did not run gives its message as the reason its section is missing.

    Returns
    -------
    str
        The HTML document.
    """
    series = analysis.get("series", {})
    steps = analysis.get("steps", {})
    reasons = {
        section: f"{step.get('state')}: {step.get('message')}"
        for section, step in (
            ("twist", steps.get("twist", {})),
            ("limits", steps.get("limits", {})),
            ("filters", steps.get("filter", {})),
        )
        if step and step.get("state") != "done"
    }
    reasons.update(unavailable or {})
    summary = {k: v for k, v in analysis.get("summary", {}).items() if not isinstance(v, dict)}
    return build_report(
        {**take, **summary},
        twist=series.get("twist") if "twist" not in reasons else None,
        limits=series.get("limits") if "limits" not in reasons else None,
        filters=series.get("filter") if "filters" not in reasons else None,
        findings=analysis.get("findings", []),
        filter_frames=series.get("frames", []),
        contact_sheet_png=contact_sheet_png,
        images=images,
        settings=settings if settings is not None else {"options": analysis.get("options", {})},
        unavailable=reasons,
    )
