"""Shared fixtures of the browser tests: a real uvicorn server and Debian's headless Chromium."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from tests.live_server import serve

from headless_chromium import CHROMIUM_ARGS, CHROMIUM_PATH
from mocapqa.api.app import create_app
from mocapqa.config import Settings

ARTIFACTS = Path(__file__).resolve().parents[1] / "artifacts"
"""Screenshots and timing figures of the browser tests (gitignored)."""


@pytest.fixture(scope="module")
def live_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """A uvicorn server on a free loopback port, with an empty data folder."""
    with serve(create_app(Settings(data_dir=tmp_path_factory.mktemp("workstation")))) as url:
        yield url


@pytest.fixture(scope="module")
def chromium() -> Iterator[object]:
    """Headless Chromium."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM_PATH, args=CHROMIUM_ARGS)
        yield browser
        browser.close()
