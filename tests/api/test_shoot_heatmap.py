"""The heat map of a shoot beyond one page: 230 takes (real analyses of the bundled demo walk
with injected twist errors and of two corpus takes, stored again under new names) paged 200 at
a time, in the take table's order."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient

from mocapqa.api.routes.shoots import HEATMAP_MAX_TAKES, MAX_OFFSET
from mocapqa.config import Settings
from mocapqa.jobs.demo import demo_paths
from mocapqa.jobs.take_task import analyse_path
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.repository import Repository
from mocapqa.store.shoots import ShootStore
from mocapqa.store.stamps import new_id
from mocapqa.store.take_writer import DoneTake

API = "/api/v1"
SOURCES = (
    "bvh/bandai/dataset-1_bow_sad_001.bvh",
    "keypoints/pose2sim/S00_P00_T00_StaticTrial/pose-3d/S00_P00_T00_StaticTrial_0-12.trc",
)
N_TAKES = 230


def _fill(settings: Settings, shoot_id: str, corpus_dir: Path) -> None:
    options = AnalysisOptions().to_json()
    paths = [demo_paths()[0], *(corpus_dir / source for source in SOURCES)]
    assert paths[0].name.endswith("_twist_errors.bvh")  # violates joint limits
    outcomes = [analyse_path(str(path), options, new_id(), new_id(), None) for path in paths]
    assert all(o["status"] == "done" for o in outcomes), outcomes
    repository = Repository(settings.resolved_database_url)
    store = ShootStore(repository.engine)
    for index in range(N_TAKES):
        outcome = outcomes[index % len(outcomes)]
        take = {
            **outcome["take"],
            "id": new_id(),
            "name": f"{index:03d}_{outcome['take']['name']}",
            "sha256": f"{index:064x}",
            "shoot_id": shoot_id,
        }
        store.record_done([DoneTake(take, new_id(), options, outcome["summary"], 0.1)])
    repository.close()


def test_heatmap_pages_through_more_than_200_takes(
    client: TestClient, settings: Settings, corpus_dir: Path
) -> None:
    shoot = client.post(f"{API}/shoots", json={"name": "big"}).json()
    sid = shoot["id"]
    _fill(settings, sid, corpus_dir)

    table: list[dict[str, Any]] = []
    for offset in (0, 200):
        page = client.get(f"{API}/shoots/{sid}/takes", params={"limit": 200, "offset": offset})
        table += page.json()["items"]
    assert len(table) == N_TAKES
    by_id = {row["take_id"]: row for row in table}

    first = client.get(f"{API}/shoots/{sid}/heatmap", params={"limit": 200}).json()
    second = client.get(f"{API}/shoots/{sid}/heatmap", params={"limit": 200, "offset": 200})
    assert second.status_code == 200, second.text
    second_page = second.json()
    assert (first["total"], first["limit"], first["offset"]) == (N_TAKES, 200, 0)
    assert (second_page["total"], second_page["offset"]) == (N_TAKES, 200)
    assert len(first["takes"]) == 200
    assert len(second_page["takes"]) == N_TAKES - 200
    # The two pages are the table's order, split at 200: every take once.
    ids = [t["take_id"] for t in first["takes"] + second_page["takes"]]
    assert ids == [row["take_id"] for row in table]
    assert first["joints"], "the twist-error walk (lowest scores: first page) violates limits"
    for heat in (first, second_page):
        assert len(heat["values"]) == len(heat["joints"])
        for joint, row in zip(heat["joints"], heat["values"], strict=True):
            for take, value in zip(heat["takes"], row, strict=True):
                stored = by_id[str(take["take_id"])]
                expected = (stored["joint_violations"] or {}).get(joint, 0.0)
                assert value == (expected if stored["violation_share"] is not None else None)
    # Descending: the same takes, the other way round where the scores differ.
    down = client.get(f"{API}/shoots/{sid}/heatmap", params={"limit": 1000, "order": "desc"})
    scores = [t["score"] for t in down.json()["takes"] if t["score"] is not None]
    assert scores == sorted(scores, reverse=True)
    assert len(down.json()["takes"]) == N_TAKES
    # A page past the end is empty, not an error; the bounds are in the schema (422).
    past = client.get(f"{API}/shoots/{sid}/heatmap", params={"offset": 5000}).json()
    assert (past["takes"], past["joints"], past["total"]) == ([], [], N_TAKES)
    for bad in (
        {"limit": HEATMAP_MAX_TAKES + 1},
        {"limit": 0},
        {"offset": -1},
        {"offset": MAX_OFFSET + 1},
        {"order": "sideways"},
    ):
        answer = client.get(f"{API}/shoots/{sid}/heatmap", params=bad)
        assert answer.status_code == 422, bad
    assert client.get(f"{API}/shoots/nope/heatmap").status_code == 404


def _table_ids(client: TestClient, sid: str, params: dict[str, Any]) -> tuple[list[str], int]:
    found: list[str] = []
    total = 0
    for offset in (0, 500):
        page = client.get(
            f"{API}/shoots/{sid}/takes", params={**params, "limit": 500, "offset": offset}
        )
        assert page.status_code == 200, page.text
        found += [row["take_id"] for row in page.json()["items"]]
        total = page.json()["total"]
    return found, total


def test_heatmap_follows_the_tables_filters_and_sort(
    client: TestClient, settings: Settings, corpus_dir: Path
) -> None:
    sid = client.post(f"{API}/shoots", json={"name": "filtered"}).json()["id"]
    _fill(settings, sid, corpus_dir)
    everything, _ = _table_ids(client, sid, {"sort": "name"})
    rows = client.get(f"{API}/shoots/{sid}/takes", params={"limit": 500}).json()["items"]
    rigs = sorted({row["rig"] for row in rows if row["rig"]})
    scores = sorted({row["score"] for row in rows if row["score"] is not None})
    assert rigs
    assert len(scores) >= 2, scores
    cases: list[dict[str, Any]] = [
        {"sort": "name", "order": "desc"},
        {"sort": "n_frames", "search": "_1"},
        {"sort": "score", "order": "desc", "has_findings": "true"},
        {"sort": "name", "has_findings": "false"},
        {"sort": "violation_share", "rig": rigs[0]},
        {"sort": "score", "min_score": scores[1], "max_score": 100},
        {"sort": "duration_s", "order": "desc", "max_score": scores[0], "status": "done"},
        {"sort": "name", "status": "failed"},
    ]
    for params in cases:
        ids, total = _table_ids(client, sid, params)
        if params.get("status") != "failed":
            assert 0 < total < N_TAKES or params == cases[0], (params, total)
        for limit, offset in ((1000, 0), (7, 3)):
            heat = client.get(
                f"{API}/shoots/{sid}/heatmap", params={**params, "limit": limit, "offset": offset}
            )
            assert heat.status_code == 200, heat.text
            body = heat.json()
            assert body["total"] == total, params
            assert [t["take_id"] for t in body["takes"]] == ids[offset : offset + limit], params
            # Only the page's takes decide its joints.
            shown = {str(t["take_id"]) for t in body["takes"]}
            by_id = {row["take_id"]: row for row in rows}
            violated = {
                joint
                for take_id in shown
                for joint, share in (by_id[take_id]["joint_violations"] or {}).items()
                if share > 0
            }
            listed = {j for t in shown for j in (by_id[t]["joint_violations"] or {})}
            assert violated <= set(body["joints"]) <= listed, params
    assert len(everything) == N_TAKES
    for bad in (
        {"min_score": 101},
        {"max_score": -1},
        {"status": "sideways"},
        {"review_status": "maybe"},
        {"has_findings": "perhaps"},
        {"search": "x" * 256},
    ):
        answer = client.get(f"{API}/shoots/{sid}/heatmap", params=bad)
        assert answer.status_code == 422, bad
