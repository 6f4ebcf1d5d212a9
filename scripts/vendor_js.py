#!/usr/bin/env python3
"""The dashboard's vendored scripts, copied from their npm packages (pinned by package-lock.json).

three.js (the 3D views) and Plotly's cartesian bundle (the charts: scatter, bar and heat map;
1.5 MB against the full bundle's 4.8 MB, whose evaluation alone held the take view's main thread
for 3 s on a loaded 2-core machine) are served from ``frontend/vendor/``, each with its licence.
The one list of what is copied: ``make js-deps`` runs this script, and so does the package build
(``setup.py``), so a wheel carries the files a checkout serves.

    python3 scripts/vendor_js.py [ROOT]

``npm ci`` runs first when ``node_modules`` is missing or older than the lock. The files are
written into the folder the package serves (``backend/mocapqa/static/frontend``, a link to
``frontend/`` in a checkout, a copy in an unpacked sdist).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

VENDORED: dict[str, tuple[str, ...]] = {
    "three": (
        "three/build/three.module.min.js",
        "three/build/three.core.min.js",
        "three/LICENSE",
    ),
    "plotly": (
        "plotly.js-cartesian-dist-min/plotly-cartesian.min.js",
        "plotly.js-cartesian-dist-min/LICENSE",
    ),
}
"""Per folder of ``frontend/vendor``, the files copied from ``node_modules``."""


def served_frontend(root: Path) -> Path:
    """The frontend folder the package serves, under ``root`` (a checkout or unpacked sdist)."""
    return root / "backend" / "mocapqa" / "static" / "frontend"


def _install(root: Path) -> None:
    stamp = root / "node_modules" / ".package-lock.json"
    lock = root / "package-lock.json"
    if stamp.is_file() and stamp.stat().st_mtime >= lock.stat().st_mtime:
        return
    npm = shutil.which("npm")
    if npm is None:
        raise SystemExit(
            "vendor_js: Expected npm (Node.js >= 20) to fetch three.js and Plotly from the npm "
            "registry as package-lock.json pins them, got none on PATH"
        )
    subprocess.run([npm, "ci", "--no-audit", "--no-fund"], cwd=root, check=True)


def vendor(root: Path) -> list[Path]:
    """Copy :data:`VENDORED` into the served frontend's ``vendor/`` (npm ci first if needed);
    returns the files written."""
    _install(root)
    written = []
    for folder, sources in VENDORED.items():
        target = served_frontend(root) / "vendor" / folder
        target.mkdir(parents=True, exist_ok=True)
        for source in sources:
            written.append(Path(shutil.copy(root / "node_modules" / source, target)))
    return written


if __name__ == "__main__":
    here = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1]
    for path in vendor(here.resolve()):
        print(f"vendor_js: {path.relative_to(here.resolve())}")
