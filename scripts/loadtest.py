#!/usr/bin/env python3
"""Bounded load test of the dashboard API on loopback.

Starts its own server (uvicorn on 127.0.0.1, a temporary data folder) unless ``--url`` names a
loopback server, then runs ``--clients`` concurrent clients, each uploading a real BVH from the
corpus, polling its run until done and downloading the corrected file. Prints p50/p95 latencies
and the error count; exits non-zero on any error. Every loop is bounded in count and time.

``--big`` also times one 10,000-frame, 31-joint take (the CMU walk tiled) and the bytes a take
view transfers on first load (page, scripts, Plotly, result and the first frame window, gzip).
``--paint`` then opens that take view in Debian's headless Chromium and prints the browser's
own first-contentful-paint time and the time until both 3D views hold data.

    .venv/bin/python scripts/loadtest.py --clients 20 --big
"""

from __future__ import annotations

import argparse
import socket
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path
from urllib.parse import urlparse

import httpx
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "backend"))
sys.path.insert(0, str(ROOT / "tests"))

from conftest import find_corpus  # noqa: E402
from headless_chromium import CHROMIUM_ARGS, CHROMIUM_PATH  # noqa: E402
from mocapqa.io.bvh import read_bvh  # noqa: E402
from mocapqa.io.bvh_write import format_bvh  # noqa: E402

DEADLINE_S = 300.0


def start_server(data_dir: Path) -> tuple[str, object, threading.Thread]:
    import uvicorn

    from mocapqa.api.app import create_app
    from mocapqa.config import Settings

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    app = create_app(Settings(data_dir=data_dir))
    server = uvicorn.Server(
        uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", access_log=False)
    )
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 30
    while not server.started:
        if time.monotonic() > deadline:
            raise SystemExit("server did not start")
        time.sleep(0.05)
    return f"http://127.0.0.1:{port}", server, thread


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def one_client(base: str, path: Path, stats: dict[str, list[float]], errors: list[str]) -> None:
    with httpx.Client(base_url=base, timeout=60) as client:
        try:
            started = time.perf_counter()
            with path.open("rb") as handle:
                response = client.post("/api/v1/takes", files={"file": (path.name, handle)})
            stats["upload_s"].append(time.perf_counter() - started)
            if response.status_code != 201:
                errors.append(f"upload {path.name}: {response.status_code} {response.text[:200]}")
                return
            run_id = response.json()["run_id"]
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline:
                poll_started = time.perf_counter()
                run = client.get(f"/api/v1/runs/{run_id}")
                stats["poll_s"].append(time.perf_counter() - poll_started)
                if run.status_code != 200:
                    errors.append(f"poll: {run.status_code}")
                    return
                status = run.json()["status"]
                if status in ("done", "failed"):
                    break
                time.sleep(0.1)
            else:
                errors.append(f"run {run_id} not finished in 120 s")
                return
            if status != "done":
                errors.append(f"run failed: {run.json()['error']}")
                return
            stats["analysed_s"].append(time.perf_counter() - started)
            stats["server_s"].append(float(run.json()["server_time_s"]))
            download = client.get(f"/api/v1/runs/{run_id}/download/bvh")
            if download.status_code != 200 or not download.content.startswith(b"HIERARCHY"):
                errors.append(f"download: {download.status_code}")
        except httpx.HTTPError as e:
            errors.append(f"{type(e).__name__}: {e}")


def big_take(base: str, corpus: Path, folder: Path, paint: bool = False) -> None:
    walk = read_bvh(corpus / "bvh/cmu/cmu_12_01_walk.bvh")
    reps = int(np.ceil(10_000 / (walk.n_frames - 1)))
    quats = np.concatenate([walk.quats[1:]] * reps)[:10_000]
    translations = np.concatenate([walk.translations[1:]] * reps)[:10_000]
    big = replace(walk, quats=quats, translations=translations, euler_hint_deg=None)
    path = folder / "cmu_walk_10000_frames.bvh"
    path.write_text(format_bvh(big))
    with httpx.Client(base_url=base, timeout=120) as client:
        started = time.perf_counter()
        with path.open("rb") as handle:
            created = client.post("/api/v1/takes", files={"file": (path.name, handle)}).json()
        uploaded = time.perf_counter() - started
        while (run := client.get(f"/api/v1/runs/{created['run_id']}").json())["status"] not in (
            "done",
            "failed",
        ):
            if time.perf_counter() - started > 120:
                raise SystemExit("big take not analysed in 120 s")
            time.sleep(0.05)
        total = time.perf_counter() - started
        result = client.get(f"/api/v1/runs/{created['run_id']}/result").json()
        steps = result["timings_s"]
        size_mb = path.stat().st_size / 1e6
        print(
            f"\n10,000 frames, {big.skeleton.n_joints} joints ({size_mb:.1f} MB), {run['status']}:"
        )
        print(f"  upload + parse (201)           {uploaded:.2f} s")
        print(f"  twist + limits                 {steps['twist_s'] + steps['limits_s']:.2f} s")
        print(f"  run server time (all, outputs) {run['server_time_s']:.2f} s")
        print(f"  upload → analysed              {total:.2f} s")
        gzip = {"Accept-Encoding": "gzip"}
        page = client.get("/", headers=gzip)
        plotly = page.text.split('name="plotly-src" content="')[1].split('"')[0]
        modules = sorted(
            p.name for p in (Path(__file__).parents[1] / "frontend" / "js").glob("*.js")
        )
        urls = [
            "/",
            plotly,
            "/static/css/app.css",
            *(f"/static/js/{name}" for name in modules),
            "/static/vendor/three/three.module.min.js",
            "/static/vendor/three/three.core.min.js",
            f"/api/v1/takes/{created['id']}",
            f"/api/v1/runs/{created['run_id']}/result",
            "/api/v1/filters",
            "/api/v1/run-options",
            f"/api/v1/runs/{created['run_id']}/frames.f32?start=0&step=1&max_frames=100",
            f"/api/v1/runs/{created['run_id']}/frames.f32?start=0&step=1&max_frames=800",
        ]
        sent = 0
        for url in urls:
            with client.stream("GET", url, headers=gzip) as response:
                sent += sum(len(chunk) for chunk in response.iter_raw())
        print(
            f"take view first load transfers {sent / 1e6:.2f} MB over {len(urls)} requests (gzip)"
        )
        if paint:
            first_paint(base + "/" + f"#/take/{created['id']}?run={created['run_id']}")


def first_paint(url: str) -> None:
    """Open ``url`` in a fresh headless Chromium; print paint and 3D-ready times (cold cache)."""
    from playwright.sync_api import sync_playwright

    # The take view marks "skeletons-drawn" when both 3D views hold the first frame.
    script = """() => new Promise((resolve) => {
      const mark = () => performance.getEntriesByName('skeletons-drawn')[0];
      const tick = () => mark() ? resolve(mark().startTime) : setTimeout(tick, 20);
      tick(); })"""
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM_PATH, args=CHROMIUM_ARGS)
        for attempt in ("cold", "warm"):
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            page.goto(url, wait_until="commit")
            views_ms = page.evaluate(script)
            fcp_ms = page.evaluate(
                "() => (performance.getEntriesByName('first-contentful-paint')[0] || {}).startTime"
            )
            print(
                f"take view ({attempt} page): first contentful paint {fcp_ms / 1000:.2f} s, "
                f"both 3D views drawn {views_ms / 1000:.2f} s"
            )
            page.close()
        browser.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=20)
    parser.add_argument("--url", default=None, help="a loopback server (default: start one)")
    parser.add_argument("--big", action="store_true", help="also time a 10,000-frame take")
    parser.add_argument(
        "--paint", action="store_true", help="with --big: time the take view in headless Chromium"
    )
    args = parser.parse_args()
    corpus = find_corpus()
    if corpus is None:
        raise SystemExit("corpus not found (set MOCAPQA_CORPUS_DIR)")
    if args.url and urlparse(args.url).hostname not in ("127.0.0.1", "localhost", "::1"):
        raise SystemExit("only loopback servers are load-tested")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        server = None
        base = args.url
        if base is None:
            base, server, thread = start_server(folder / "data")
        files = [
            *sorted((corpus / "bvh" / "misc").glob("*.bvh")),
            corpus / "bvh/cmu/cmu_12_01_walk.bvh",
        ]
        stats: dict[str, list[float]] = {
            k: [] for k in ("upload_s", "poll_s", "analysed_s", "server_s")
        }
        errors: list[str] = []
        started = time.perf_counter()
        with ThreadPoolExecutor(max_workers=args.clients) as pool:
            futures = [
                pool.submit(one_client, base, files[i % len(files)], stats, errors)
                for i in range(args.clients)
            ]
            for future in futures:
                future.result(timeout=DEADLINE_S)
        wall = time.perf_counter() - started
        print(f"{args.clients} concurrent clients, {wall:.1f} s wall, {len(errors)} errors")
        print(f"{'measure':<28}{'n':>5}{'p50 (s)':>10}{'p95 (s)':>10}")
        for key, label in (
            ("upload_s", "upload (201)"),
            ("poll_s", "status poll"),
            ("analysed_s", "upload → analysed"),
            ("server_s", "run server time"),
        ):
            values = stats[key]
            p50, p95 = percentile(values, 50), percentile(values, 95)
            print(f"{label:<28}{len(values):>5}{p50:>10.3f}{p95:>10.3f}")
        for error in errors[:10]:
            print("error:", error)
        if args.big:
            big_take(base, corpus, folder, paint=args.paint)
        if server is not None:
            server.should_exit = True  # type: ignore[attr-defined]
            thread.join(timeout=10)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
