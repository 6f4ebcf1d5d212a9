"""The shoot table's pages on SQLite and PostgreSQL: every page, both directions, filtered or
not, is the slice of one reference order (the sort column with missing values last, ties by
name then id), the same across page boundaries between takes with and without a value."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest

from mocapqa.jobs.take_task import analyse_path
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.repository import Repository
from mocapqa.store.shoot_pages import TakeFilter
from mocapqa.store.shoots import ShootStore
from mocapqa.store.stamps import new_id
from mocapqa.store.take_writer import DoneTake

WALK = "bvh/cmu/cmu_12_01_walk.bvh"
N_TAKES = 41


@pytest.fixture(scope="module")
def analysed(corpus_dir: Path) -> dict[str, Any]:
    """A real analysis of the CMU walk (its take values and run summary)."""
    outcome = analyse_path(
        str(corpus_dir / WALK), AnalysisOptions().to_json(), new_id(), new_id(), None
    )
    assert outcome["status"] == "done", outcome
    return outcome


def _reference(rows: list[dict[str, Any]], key: str, descending: bool) -> list[str]:
    valued = sorted(
        (r for r in rows if r[key] is not None), key=lambda r: (r["name"], r["take_id"])
    )
    valued.sort(key=lambda r: r[key], reverse=descending)  # stable: ties stay by name, id
    missing = sorted((r for r in rows if r[key] is None), key=lambda r: (r["name"], r["take_id"]))
    return [r["take_id"] for r in valued + missing]


def test_pages_are_slices_of_one_order(repository: Repository, analysed: dict[str, Any]) -> None:
    store = ShootStore(repository.engine)
    shoot = str(store.create("order")["id"])
    options = AnalysisOptions().to_json()
    for index in range(N_TAKES):
        summary = copy.deepcopy(analysed["summary"])
        # Scores with ties and, for every fifth take, none (a summary without a score).
        summary["qa"]["score"] = None if index % 5 == 0 else float((index * 7) % 6) * 10.0
        take = {
            **analysed["take"],
            "id": new_id(),
            "name": f"take_{(index * 13) % N_TAKES:02d}{'_walk' if index % 2 else ''}.bvh",
            "sha256": f"{index + 1:064x}",
            "shoot_id": shoot,
        }
        store.record_done([DoneTake(take, new_id(), options, summary, 0.1)])
    everything, total = store.page(shoot, 500, 0, "name")
    assert total == N_TAKES
    assert sum(r["score"] is None for r in everything) == 9

    for filters, subset in (
        (None, everything),
        (TakeFilter(search="walk"), [r for r in everything if "walk" in r["name"]]),
    ):
        for sort in ("score", "name", "n_frames"):
            for descending in (False, True):
                expected = _reference(subset, sort, descending)
                for size in (1, 4, 7, 50):
                    got: list[str] = []
                    for offset in range(0, len(expected) + size, size):
                        page, counted = store.page(shoot, size, offset, sort, descending, filters)
                        assert counted == len(expected)
                        assert len(page) == max(0, min(size, len(expected) - offset))
                        got += [r["take_id"] for r in page]
                    assert got == expected, (sort, descending, size, filters)
    full = store.page(shoot, 3, 0, "score")[0][0]
    assert full["format"] == analysed["take"]["format"]  # the take's columns are joined
    assert full["joint_violations"] is not None
