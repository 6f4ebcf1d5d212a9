"""Take-list thumbnails: the middle frame's skeleton as a small SVG, drawn from a run's points.

Missing points (NaN in ``points.npz``) and the bones that end at them are left out.

The view is frontal (X to the right, the rig's up axis, Y, upward), scaled to fit. Before a run
has finished the thumbnail is a neutral placeholder.
"""

from __future__ import annotations

from html import escape

import numpy as np

from mocapqa.jobs.run_folder import RunFolder
from mocapqa.jobs.stored_run import load_points, load_report
from mocapqa.store.files import FileStore

__all__ = ["placeholder_svg", "thumbnail_svg"]

SIZE_PX = 96


def placeholder_svg(label: str) -> str:
    """A grey tile with a label."""
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{SIZE_PX}" height="{SIZE_PX}">'
        f'<rect width="100%" height="100%" fill="#eceff3"/>'
        f'<text x="50%" y="54%" font-size="11" text-anchor="middle" fill="#6b7280">'
        f"{escape(label[:14])}</text></svg>"
    )


def thumbnail_svg(files: FileStore, run_id: str | None, label: str) -> str:
    """The skeleton of a run's middle frame, or a placeholder while there is none."""
    if run_id is None:
        return placeholder_svg(label)
    folder = RunFolder.of(files, run_id)
    try:
        points = load_points(folder.points, ("raw",))["raw"]
        report = load_report(folder.report)
    except (OSError, ValueError, KeyError):
        return placeholder_svg("analysing…")
    if points.shape[0] == 0:
        return placeholder_svg(label)
    frame = points[points.shape[0] // 2, :, :2].astype(np.float64)
    seen = np.asarray(np.isfinite(frame).all(axis=1), dtype=bool)
    if not seen.any():
        return placeholder_svg(label)
    parents = report.get("points", {}).get("parents", [])
    low, high = frame[seen].min(axis=0), frame[seen].max(axis=0)
    scale = (SIZE_PX - 12) / max(float((high - low).max()), 1e-9)
    xy = (frame - (low + high) / 2) * scale
    xy[:, 1] *= -1
    xy += SIZE_PX / 2
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{SIZE_PX}" height="{SIZE_PX}">',
        '<rect width="100%" height="100%" fill="#f5f7fa"/>',
    ]
    for child, parent in enumerate(parents):
        if 0 <= parent < len(xy) and child < len(xy) and seen[parent] and seen[child]:
            (x1, y1), (x2, y2) = xy[parent], xy[child]
            parts.append(
                f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" '
                'stroke="#1f4e79" stroke-width="2" stroke-linecap="round"/>'
            )
    if not any(p >= 0 for p in parents):
        parts += [
            f'<circle cx="{x:.1f}" cy="{y:.1f}" r="1.6" fill="#1f4e79"/>' for x, y in xy[seen]
        ]
    parts.append("</svg>")
    return "".join(parts)
