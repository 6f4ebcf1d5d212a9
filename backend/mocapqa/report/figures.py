"""Plotly figures of a report: twist timeline, limits timeline, filter weights.

Conventions
-----------
Each builder takes an analysis' ``to_json()`` dict and returns a ``plotly.graph_objects``
Figure (or None when the dict holds nothing to plot). Frames are on the x axis, 0-based;
angles in degrees. Flagged intervals are shaded bands so they stay visible when a series is
long. plotly is imported inside the builders so importing the report package stays cheap.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["filter_weights_figure", "limits_timeline_figure", "twist_timeline_figure"]

_LAYOUT: dict[str, Any] = {
    "template": "plotly_white",
    "height": 320,
    "margin": {"l": 60, "r": 20, "t": 40, "b": 45},
    "legend": {"orientation": "h", "y": -0.25},
    "xaxis": {"title": {"text": "frame"}},
}


def _bands(findings: Sequence[Mapping[str, Any]], color: str) -> list[dict[str, Any]]:
    return [
        {
            "type": "rect",
            "xref": "x",
            "yref": "paper",
            "x0": f["start_frame"] - 0.5,
            "x1": f["end_frame"] + 0.5,
            "y0": 0,
            "y1": 1,
            "fillcolor": color,
            "opacity": 0.15,
            "line": {"width": 0},
            "layer": "below",
        }
        for f in findings
    ]


def _lines_figure(
    lines: Sequence[tuple[str, Sequence[Any], Sequence[Any]]],
    hover: str,
    title: str,
    y_title: str,
    shapes: list[dict[str, Any]],
) -> Any:
    """A Plotly figure of one line per ``(name, frames, values)``, hovered as ``frame … <br>
    hover``, with the title, the y axis' title and the shaded bands."""
    import plotly.graph_objects as go

    fig = go.Figure()
    for name, frames, values in lines:
        fig.add_trace(
            go.Scatter(
                x=frames,
                y=values,
                mode="lines",
                name=name,
                hovertemplate=f"frame %{{x}}<br>{hover}<extra>%{{fullData.name}}</extra>",
            )
        )
    fig.update_layout(
        **_LAYOUT,
        title={"text": title},
        yaxis={"title": {"text": y_title}},
        shapes=shapes,
    )
    return fig


def twist_timeline_figure(
    twist: Mapping[str, Any], findings: Sequence[Mapping[str, Any]] = ()
) -> Any:
    """Removed twist offset per chain over time, flagged intervals shaded.

    Parameters
    ----------
    twist : mapping
        A twist analysis' ``to_json()`` (``frames`` and ``chains[*].offset_deg``).
    findings : sequence of mapping
        Twist findings to shade.
    """

    frames = twist.get("frames", [])
    chains = twist.get("chains", [])
    if not frames or not chains:
        return None
    lines = [(str(chain.get("joint")), frames, chain.get("offset_deg", [])) for chain in chains]
    return _lines_figure(
        lines,
        "offset %{y:.1f}°",
        "Twist offset removed per chain",
        "offset (deg)",
        _bands(findings, "#d62728"),
    )


def limits_timeline_figure(
    limits: Mapping[str, Any], findings: Sequence[Mapping[str, Any]] = (), max_joints: int = 8
) -> Any:
    """Distance outside the limits over time for the joints that leave them most.

    Parameters
    ----------
    limits : mapping
        A limits report's ``to_json()`` (``joints[*].frames``), or the pipeline's heat map
        (``joints`` names, ``frames``, ``score_deg`` as joints × frames).
    findings : sequence of mapping
        Limit findings to shade.
    max_joints : int
        Most joints drawn, by largest score.
    """

    series: list[tuple[str, list[Any], list[float]]] = []
    joints = limits.get("joints", [])
    if joints and isinstance(joints[0], str):
        frames = list(limits.get("frames", []))
        for name, row in zip(joints, limits.get("score_deg", []), strict=False):
            series.append((name, frames, list(row)))
    else:
        for joint in joints:
            data = joint.get("frames", {})
            series.append(
                (str(joint.get("name")), data.get("frame", []), data.get("score_deg", []))
            )
    series = [s for s in series if s[2] and max(s[2]) > 0]
    series.sort(key=lambda s: -max(s[2]))
    if not series:
        return None
    return _lines_figure(
        series[:max_joints],
        "outside by %{y:.1f}°",
        "Distance outside joint limits",
        "score (deg)",
        _bands(findings, "#ff7f0e"),
    )


def filter_weights_figure(filters: Mapping[str, Any], frames: Sequence[int] = ()) -> Any:
    """Mean blend weight of each filter over time (adaptive filter), stacked to 1.

    Parameters
    ----------
    filters : mapping
        A keypoint filter result's ``to_json()`` (``timeline_frames``, ``weights_mean``,
        ``weight_names``), or the pipeline's filter series (``weights`` as name →
        ``{"mean": [...]}``).
    frames : sequence of int
        Frame numbers of the pipeline's series (ignored for ``to_json()`` input).
    """
    import plotly.graph_objects as go

    lines: list[tuple[str, list[float]]] = []
    x: Sequence[int]
    if isinstance(filters.get("weights"), Mapping):
        x = frames
        for name, data in filters["weights"].items():
            lines.append((str(name), list(data.get("mean", []))))
    else:
        x = filters.get("timeline_frames", [])
        rows = filters.get("weights_mean") or []
        for k, name in enumerate(filters.get("weight_names", [])):
            lines.append((str(name), [row[k] for row in rows]))
    lines = [line for line in lines if line[1]]
    if not lines:
        return None
    if not x:
        x = list(range(len(lines[0][1])))
    fig = go.Figure()
    for name, values in lines:
        fig.add_trace(
            go.Scatter(
                x=list(x),
                y=values,
                mode="lines",
                stackgroup="weights",
                name=name,
                hovertemplate="frame %{x}<br>weight %{y:.2f}<extra>%{fullData.name}</extra>",
            )
        )
    fig.update_layout(
        **_LAYOUT,
        title={"text": f"Filter weights ({filters.get('method', 'adaptive')})"},
        yaxis={"title": {"text": "weight"}, "range": [0, 1]},
    )
    return fig
