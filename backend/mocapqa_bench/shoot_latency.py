"""The shoot table's API latency for ``mocapqa bench batch``: a shoot of many takes whose
summaries repeat a batch's real ones, and the shoot view's requests timed through the app."""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Any

__all__ = ["api_latency", "stored_rows"]


def _latency(client: Any, url: str, params: dict[str, Any], repeats: int) -> tuple[float, float]:
    times = []
    for _ in range(repeats):
        clock = time.perf_counter()
        response = client.get(url, params=params)
        times.append((time.perf_counter() - clock) * 1000)
        if response.status_code != 200:
            raise RuntimeError(f"{url} answered {response.status_code}: {response.text[:200]}")
    times.sort()
    return statistics.median(times), times[min(len(times) - 1, int(0.95 * len(times)))]


def stored_rows(repository: Any) -> list[dict[str, Any]]:
    """Take values and run summaries of every stored take (to replicate for the API)."""
    from sqlalchemy import select

    from mocapqa.store.tables import runs, takes

    columns = [
        takes.c[name]
        for name in ("format", "kind", "size_bytes", "n_frames", "fps", "n_joints", "file_name")
    ]
    with repository.engine.connect() as conn:
        found = conn.execute(
            select(*columns, runs.c.summary).join(runs, runs.c.take_id == takes.c.id)
        ).mappings()
        return [
            {"take": {k: r[k] for k in r if k != "summary"}, "summary": r["summary"]} for r in found
        ]


def _fill_shoot(database_url: str, rows: list[dict[str, Any]], n_takes: int) -> str:
    """A shoot of ``n_takes`` takes whose summaries repeat the batch's real ones."""
    from sqlalchemy import insert

    from mocapqa.store.qa import QA_COLUMNS
    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore
    from mocapqa.store.stamps import new_id, utc_now
    from mocapqa.store.tables import runs, take_qa, takes
    from mocapqa.store.upgrade import drop_database

    repository = Repository(database_url)
    drop_database(repository.engine)
    repository.close()
    repository = Repository(database_url)
    shoot = ShootStore(repository.engine).create("bench")
    now = utc_now()
    take_rows, run_rows, qa_rows = [], [], []
    for index in range(n_takes):
        source = rows[index % len(rows)]
        take_id, run_id = new_id(), new_id()
        take_rows.append(
            {
                **source["take"],
                "id": take_id,
                "name": f"take_{index:05d}.bvh",
                "sha256": f"{index:064x}",
                "shoot_id": shoot["id"],
                "created_at": now,
            }
        )
        run_rows.append(
            {
                "id": run_id,
                "take_id": take_id,
                "status": "done",
                "progress": 100,
                "step": "done",
                "options": {},
                "input_sha256": f"{index:064x}",
                "version": "bench",
                "summary": source["summary"],
                "created_at": now,
            }
        )
        qa = source["summary"]["qa"]
        qa_rows.append(
            {
                "take_id": take_id,
                "shoot_id": shoot["id"],
                "name": f"take_{index:05d}.bvh",
                "kind": "motion",
                "created_at": now,
                "run_id": run_id,
                "status": "done",
                "review_status": "unreviewed",
                "reviewer": None,
                "n_findings": source["summary"]["n_findings"],
                **{k: qa.get(k) for k in QA_COLUMNS},
            }
        )
    with repository.engine.begin() as conn:
        for table, values in ((takes, take_rows), (runs, run_rows), (take_qa, qa_rows)):
            for start in range(0, len(values), 1000):
                conn.execute(insert(table), values[start : start + 1000])
    repository.close()
    return str(shoot["id"])


def api_latency(
    rows: list[dict[str, Any]], n_takes: int, targets: list[tuple[str, str]], data_dir: Path
) -> Any:
    """The shoot view's requests on a shoot of ``n_takes`` takes repeating ``rows`` (stored
    take values and summaries), through the app, on each ``(label, database URL)``: a table
    of p50 / p95 ms over 40 requests after 3 warm-ups."""
    from fastapi.testclient import TestClient
    from rich.table import Table

    from mocapqa.api.app import create_app
    from mocapqa.config import Settings

    latency = Table("database", "request", "p50 ms", "p95 ms")
    for label, url in targets:
        shoot_id = _fill_shoot(url, rows, n_takes)
        settings = Settings(data_dir=data_dir, database_url=url, allowed_hosts=["testserver"])
        with TestClient(create_app(settings)) as client:
            base = f"/api/v1/shoots/{shoot_id}"
            filtered = {"sort": "violation_share", "order": "desc", "min_score": 50}
            requests: tuple[tuple[str, str, dict[str, Any]], ...] = (
                ("list page (50, by created_at)", f"{base}/takes", {"sort": "created_at"}),
                ("sort by score", f"{base}/takes", {"sort": "score", "offset": 5000}),
                ("filter + search", f"{base}/takes", {**filtered, "search": "take_01"}),
                ("heat map (200 takes)", f"{base}/heatmap", {}),
                ("heat map, filtered and sorted", f"{base}/heatmap", filtered),
                ("next for review", f"{base}/next", {}),
                ("shoot list", "/api/v1/shoots", {}),
            )
            for name, path, params in requests:
                _latency(client, path, params, 3)
                p50, p95 = _latency(client, path, params, 40)
                latency.add_row(label, name, f"{p50:.1f}", f"{p95:.1f}")
    return latency
