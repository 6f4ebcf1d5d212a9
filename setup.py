"""Package build hook: the wheel carries the dashboard's vendored three.js and Plotly.

Everything else is declared in pyproject.toml. Before the package's files are collected, the
vendored scripts are copied from the npm packages package-lock.json pins
(``scripts/vendor_js.py``, the list ``make js-deps`` uses), so ``pip install mocapqa-*.whl``
serves a dashboard that draws, with no ``make`` and no npm on the machine that installs it.
Building needs npm (Node.js >= 20) unless the files are already there.
"""

from __future__ import annotations

import runpy
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent


class BuildWithVendoredScripts(build_py):
    """``build_py`` that first copies the vendored scripts into the served frontend."""

    def run(self) -> None:
        helpers = runpy.run_path(str(ROOT / "scripts" / "vendor_js.py"))
        frontend = helpers["served_frontend"](ROOT)
        wanted = [
            frontend / "vendor" / folder / Path(source).name
            for folder, sources in helpers["VENDORED"].items()
            for source in sources
        ]
        if not all(path.is_file() for path in wanted):
            helpers["vendor"](ROOT)
        super().run()


setup(cmdclass={"build_py": BuildWithVendoredScripts})
