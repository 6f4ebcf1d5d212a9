"""The package as a user installs it: an sdist and a wheel built from the repository's tracked
files alone (no ``frontend/vendor``, no ``node_modules``), the wheel installed in a clean
virtual environment, and ``mocapqa serve --demo`` from that environment drawing a take in
Debian's Chromium. Before, a wheel served a take page that failed with "Failed to fetch
dynamically imported module: /static/js/scene3d.js" and drew no skeleton, and a checkout without
the vendored files started without a word.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from headless_chromium import CHROMIUM_ARGS, CHROMIUM_PATH
from mocapqa.cli.main import main
from mocapqa_bench.api_load import ServerProcess

ROOT = Path(__file__).resolve().parents[1]
BOUND_S = 900
"""Generous bound on building and installing (a loaded 2-core machine, packages from the cache)."""


def test_a_checkout_without_the_vendored_scripts_refuses_to_serve(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "index.html").write_text("<!doctype html>")
    monkeypatch.setattr("mocapqa.api.app.frontend_dir", lambda: tmp_path)
    monkeypatch.setenv("MOCAPQA_DATA_DIR", str(tmp_path / "data"))
    assert main(["serve", "--port", "1"]) == 4
    message = capsys.readouterr().err
    assert "three.module.min.js" in message
    assert "make js-deps" in message
    assert not (tmp_path / "data").exists()  # refused before anything was made


def _tracked_tree(target: Path) -> Path:
    """The repository's files that are not ignored (what a clone of it has) copied to
    ``target``."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        check=True,
        capture_output=True,
    ).stdout.split(b"\0")
    for name in filter(None, listed):
        source = ROOT / name.decode()
        destination = target / name.decode()
        destination.parent.mkdir(parents=True, exist_ok=True)
        if source.is_symlink():
            destination.symlink_to(os.readlink(source))
        elif source.is_file():
            shutil.copy2(source, destination)
    return target


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A clean virtual environment with the wheel built from an sdist of the tracked files;
    its ``bin`` folder."""
    work = tmp_path_factory.mktemp("wheel")
    tree = _tracked_tree(work / "tree")
    assert not (tree / "frontend" / "vendor").exists()
    dist = work / "dist"
    subprocess.run(
        [sys.executable, "-m", "build", "--outdir", str(dist), str(tree)],
        check=True,
        capture_output=True,
        timeout=BOUND_S,
    )
    wheel = next(dist.glob("mocapqa-*.whl"))
    assert next(dist.glob("mocapqa-*.tar.gz"))
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    for name in ("three/three.module.min.js", "three/LICENSE", "plotly/plotly-cartesian.min.js"):
        assert f"mocapqa/static/frontend/vendor/{name}" in names
    venv = work / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=BOUND_S)
    subprocess.run(
        [str(venv / "bin" / "pip"), "install", "--quiet", str(wheel)],
        check=True,
        capture_output=True,
        timeout=BOUND_S,
    )
    return venv / "bin"


@pytest.mark.slow
@pytest.mark.browser
def test_the_installed_wheel_serves_a_dashboard_that_draws_the_demo_take(
    installed: Path, tmp_path: Path
) -> None:
    from playwright.sync_api import sync_playwright

    located = subprocess.run(
        [str(installed / "python"), "-c", "import mocapqa, sys; print(mocapqa.__file__)"],
        check=True,
        capture_output=True,
        text=True,
        cwd=tmp_path,
    ).stdout
    assert str(installed.parent) in located  # the wheel's copy, not the checkout

    server = ServerProcess(
        tmp_path / "data",
        {"PATH": f"{installed}:{os.environ['PATH']}"},
        command=[str(installed / "mocapqa"), "serve", "--demo"],
        cwd=tmp_path,
    )
    try:
        link = next(
            line.split(" at ", 1)[1].strip()
            for line in server.log().splitlines()
            if "sign in (once" in line
        )
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM_PATH, args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            errors: list[str] = []
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(link)  # signs the admin in and lands on the take list
            page.wait_for_selector("#take-list tbody tr", timeout=120_000)
            page.locator("#take-list tbody tr td").nth(1).click()  # a row opens its take
            page.wait_for_selector("main[data-ready='1']", timeout=120_000)
            page.wait_for_function("() => window.mocapqaViews && window.mocapqaViews.points > 0")
            drawn = int(page.evaluate("() => window.mocapqaViews.points"))
            browser.close()
    finally:
        server.stop()
    assert drawn > 0
    assert errors == []
