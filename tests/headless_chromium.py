"""How every browser test (and the load test's paint timing) starts Debian's Chromium.

Headless, no sandbox (tests run as root), no GPU, and no background networking: the machine's
network is closed, and Chromium's own update and sync traffic would only fail and slow it.
"""

from __future__ import annotations

__all__ = ["CHROMIUM_ARGS", "CHROMIUM_PATH"]

# Debian's package, installed by `make test` (system-deps) when missing.
CHROMIUM_PATH = "/usr/bin/chromium"
# Launch flags for Playwright's `chromium.launch(args=...)`.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-dev-shm-usage",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
