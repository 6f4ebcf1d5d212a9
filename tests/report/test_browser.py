"""The report written by ``mocapqa report`` opens offline in Chromium with its plots and images."""

from __future__ import annotations

from pathlib import Path

import pytest

from headless_chromium import CHROMIUM_ARGS, CHROMIUM_PATH
from mocapqa.cli.main import main

# A take with twist intervals, limb spins and joint-limit violations (its real knee errors).
TAKE = "bvh/cmu/iclone/005_05.bvh"


@pytest.fixture(scope="module")
def report_file(corpus_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    output = tmp_path_factory.mktemp("report") / "report.html"
    assert main(["report", str(corpus_dir / TAKE), "-o", str(output)]) == 0
    return output


@pytest.mark.render
@pytest.mark.browser
def test_report_opens_offline_with_plots_and_contact_sheet(report_file: Path) -> None:
    from playwright.sync_api import sync_playwright

    requested: list[str] = []
    console_errors: list[str] = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=CHROMIUM_PATH, headless=True, args=CHROMIUM_ARGS
        )
        try:
            context = browser.new_context(offline=True, viewport={"width": 1200, "height": 900})

            def block(route: object) -> None:
                url = route.request.url  # type: ignore[attr-defined]
                if url.startswith("file:"):
                    route.continue_()  # type: ignore[attr-defined]
                else:
                    requested.append(url)
                    route.abort()  # type: ignore[attr-defined]

            context.route("**/*", block)
            page = context.new_page()
            page.on(
                "console", lambda m: console_errors.append(m.text) if m.type == "error" else None
            )
            page.goto(report_file.as_uri(), wait_until="load")
            page.wait_for_function(
                "document.querySelectorAll('.js-plotly-plot .main-svg').length >= 2",
                timeout=30_000,
            )
            assert page.evaluate("typeof Plotly") == "object"
            plots = page.evaluate("document.querySelectorAll('.js-plotly-plot').length")
            traces = page.evaluate(
                "Array.from(document.querySelectorAll('.js-plotly-plot'))"
                ".map(d => d.querySelectorAll('.scatterlayer .trace').length)"
            )
            sheet_width = page.evaluate("document.querySelector('img.sheet').naturalWidth")
            rows = page.evaluate("document.querySelectorAll('#findings ~ table tr').length")
            page.screenshot(path=str(report_file.with_suffix(".png")), full_page=True)
        finally:
            browser.close()
    assert requested == []
    assert console_errors == []
    assert plots == 2  # twist and limits timelines (no filter for a BVH take)
    assert all(n > 0 for n in traces)
    assert sheet_width > 300
    assert rows > 1
