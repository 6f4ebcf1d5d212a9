"""What Plotly alone costs the page's main thread, on an empty page, in the tests' Chromium.

Usage (from the repository root, after ``make`` has vendored the JavaScript):

    python scripts/plotly_cost.py [--runs 8]

Each run opens a fresh page holding nothing but a chart box and a long-task observer, adds the
dashboard's Plotly bundle (``frontend/vendor/plotly/plotly-cartesian.min.js``, served locally),
and, in a later task, plots 20 line traces of 2,000 samples (the twist chart's size). It prints
per run the 1-minute load average, the longest main-thread task while the bundle was evaluated
and the first plot's task, in milliseconds. Nothing of the dashboard runs, so these are floors
for the take view: the "answers input within 100 ms" figure of docs/dashboard.md cannot be
lower than them while Plotly is on the page.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import json
import os
import sys
import tempfile
import threading
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUNDLE = ROOT / "frontend" / "vendor" / "plotly" / "plotly-cartesian.min.js"

PAGE = """<!doctype html><html><body><div id="chart" style="width:1000px;height:300px"></div>
<script>
window.longTasks = [];
new PerformanceObserver((list) => {
  for (const entry of list.getEntries()) window.longTasks.push([entry.startTime, entry.duration]);
}).observe({type: "longtask", buffered: true});
</script></body></html>"""

MEASURE = """() => new Promise((resolve) => {
  const script = document.createElement("script");
  script.src = "plotly.js";
  script.onload = () => {
    const evaluated = performance.now();
    setTimeout(async () => {
      const x = Array.from({length: 2000}, (_, i) => i / 60);
      const traces = Array.from({length: 20}, (_, k) => ({
        x, y: x.map((t) => Math.sin(t + k)), type: "scatter", mode: "lines"}));
      await Plotly.newPlot("chart", traces, {margin: {t: 10}});
      setTimeout(() => {
        const before = window.longTasks.filter(([start]) => start < evaluated);
        const after = window.longTasks.filter(([start]) => start >= evaluated);
        const longest = (tasks) => Math.round(Math.max(0, ...tasks.map(([, ms]) => ms)));
        resolve({evaluate_ms: longest(before), first_plot_ms: longest(after)});
      }, 100);
    }, 100);
  };
  document.head.appendChild(script);
})"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=8)
    args = parser.parse_args()
    if not BUNDLE.is_file():
        sys.exit(f"error: {BUNDLE} is missing: run `make` first")
    sys.path.insert(0, str(ROOT / "tests"))
    from playwright.sync_api import sync_playwright

    from headless_chromium import CHROMIUM_ARGS, CHROMIUM_PATH

    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "index.html").write_text(PAGE)
        (Path(folder) / "plotly.js").symlink_to(BUNDLE)

        class Handler(http.server.SimpleHTTPRequestHandler):
            def log_message(self, format: str, *args: object) -> None:
                pass

        server = http.server.ThreadingHTTPServer(
            ("127.0.0.1", 0), functools.partial(Handler, directory=folder)
        )
        threading.Thread(target=server.serve_forever, daemon=True).start()
        url = f"http://127.0.0.1:{server.server_address[1]}/index.html"
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM_PATH, args=CHROMIUM_ARGS)
            for run in range(args.runs):
                page = browser.new_page()
                page.goto(url)
                load = os.getloadavg()[0]
                figures = page.evaluate(MEASURE)
                print(json.dumps({"run": run, "load_1min": round(load, 2), **figures}), flush=True)
                page.close()
            browser.close()
        server.shutdown()


if __name__ == "__main__":
    main()
