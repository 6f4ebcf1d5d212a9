"""The feet figures of a take's row on SQLite and PostgreSQL: skate, penetration and floating
counts and the largest skate with its unit, from real analyses of a BVH take given a slide and
a TRC take with a skate (the same figures as ``mocapqa feet check``); sorted and filtered in the
shoot table, empty (not 0) for a run that did not check the feet, and filled by migration 0010
from the summaries runs made before it."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
from sqlalchemy import select
from tests.store.skating_take import STANDING_BVH, drifted_bvh

from mocapqa.io.formats import read_take
from mocapqa.jobs.take_task import analyse_path
from mocapqa.pipeline.feet import check_take_feet, feet_report_json
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.qa import FEET_COLUMNS, sync_take
from mocapqa.store.repository import Repository
from mocapqa.store.shoot_pages import TakeFilter
from mocapqa.store.shoots import ShootStore
from mocapqa.store.stamps import new_id
from mocapqa.store.tables import take_qa
from mocapqa.store.take_writer import DoneTake
from mocapqa.store.upgrade import downgrade_database, head_revision, upgrade_database

BVH = "standing_drifted.bvh"  # a slide injected (tests/store/skating_take.py): % of the height
TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
FEET_ONLY = AnalysisOptions(checks=("feet",)).to_json()


def _analysed(folder: Path, relative: str) -> dict[str, Any]:
    outcome = analyse_path(str(folder / relative), FEET_ONLY, new_id(), new_id(), None)
    assert outcome["status"] == "done", outcome
    return outcome


def _feet_check(folder: Path, relative: str) -> dict[str, Any]:
    """What ``mocapqa feet check --json`` prints for the take."""
    points, report, skipped = check_take_feet(read_take(folder / relative))
    return feet_report_json(points, report, skipped)


@pytest.fixture(scope="module")
def folders(corpus_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Where each take is: the corpus, or (the drifted BVH) a folder of the test's own."""
    made = drifted_bvh(corpus_dir, tmp_path_factory.mktemp("feet"))
    assert made.name == BVH
    return {BVH: made.parent, TRC: corpus_dir}


@pytest.fixture(scope="module")
def analysed(folders: dict[str, Path]) -> dict[str, dict[str, Any]]:
    return {name: _analysed(folders[name], name) for name in (BVH, TRC)}


def _record(store: ShootStore, shoot: str, outcome: dict[str, Any], name: str) -> str:
    take = {**outcome["take"], "id": new_id(), "name": name, "sha256": new_id() * 2,
            "shoot_id": shoot}  # fmt: skip
    store.record_done([DoneTake(take, new_id(), FEET_ONLY, outcome["summary"], 0.1)])
    return str(take["id"])


def _row(repository: Repository, take_id: str) -> dict[str, Any]:
    with repository.engine.connect() as conn:
        found = conn.execute(select(take_qa).where(take_qa.c.take_id == take_id)).mappings()
        return dict(found.one())


def _feet(row: dict[str, Any]) -> tuple[Any, ...]:
    return tuple(row[k] for k in FEET_COLUMNS)


def test_the_standing_take_skates_only_with_the_slide(
    corpus_dir: Path, folders: dict[str, Path]
) -> None:
    def skates(folder: Path, name: str) -> int:
        return sum(f["kind"] == "skate" for f in _feet_check(folder, name)["findings"])

    assert skates(corpus_dir, STANDING_BVH) == 0
    assert skates(folders[BVH], BVH) >= 1
    # Checked and clean: no skate, so no largest one either (not 0).
    qa = _analysed(corpus_dir, STANDING_BVH)["summary"]["qa"]
    assert (qa["foot_skates"], qa["foot_worst_skate"], qa["foot_skate_unit"]) == (0, None, None)


def test_a_take_s_row_has_the_feet_check_s_skates_and_its_largest(
    repository: Repository, folders: dict[str, Path], analysed: dict[str, dict[str, Any]]
) -> None:
    store = ShootStore(repository.engine)
    shoot = str(store.create("feet")["id"])
    for relative, unit in ((BVH, "% height"), (TRC, "cm")):
        take_id = _record(store, shoot, analysed[relative], Path(relative).name)
        row = _row(repository, take_id)
        check = _feet_check(folders[relative], relative)
        skates = [f for f in check["findings"] if f["kind"] == "skate"]
        assert row["foot_skates"] == len(skates) >= 1
        sizes = [f["size_cm"] if unit == "cm" else 100 * f["size_rel_height"] for f in skates]
        assert row["foot_worst_skate"] == pytest.approx(max(sizes), abs=1e-3)
        assert row["foot_skate_unit"] == unit
        for column, kind in (("foot_penetrations", "penetration"), ("foot_floating", "floating")):
            assert row[column] == sum(f["kind"] == kind for f in check["findings"])
        # The row written with the take is the one the store rebuilds.
        with repository.engine.begin() as conn:
            sync_take(conn, take_id)
        assert _row(repository, take_id) == row


def _shoot_of_five(
    store: ShootStore, analysed: dict[str, dict[str, Any]]
) -> tuple[str, dict[str, str]]:
    """A shoot with the BVH and TRC takes, a clean take (feet checked, no skate), a take whose
    run did not check the feet and one whose run was made before the feet figures."""
    shoot = str(store.create("five")["id"])
    clean = copy.deepcopy(analysed[BVH])
    clean["summary"]["qa"].update(foot_skates=0, foot_worst_skate=None, foot_skate_unit=None,
                                  foot_penetrations=0, foot_floating=0)  # fmt: skip
    unchecked = copy.deepcopy(analysed[BVH])
    unchecked["summary"]["qa"].update(dict.fromkeys(FEET_COLUMNS))
    older = copy.deepcopy(analysed[BVH])
    for column in (*FEET_COLUMNS, "foot_contacts", "foot_jitter"):
        del older["summary"]["qa"][column]
    names = {
        "bvh": (analysed[BVH], "a_bvh.bvh"),
        "trc": (analysed[TRC], "b_trc.trc"),
        "clean": (clean, "c_clean.bvh"),
        "unchecked": (unchecked, "d_unchecked.bvh"),
        "older": (older, "e_older.bvh"),
    }
    return shoot, {key: _record(store, shoot, *value) for key, value in names.items()}


def test_the_shoot_table_sorts_and_filters_by_the_feet_figures(
    repository: Repository, analysed: dict[str, dict[str, Any]]
) -> None:
    store = ShootStore(repository.engine)
    shoot, ids = _shoot_of_five(store, analysed)
    rows = {r["take_id"]: r for r in store.page(shoot, 50)[0]}
    # No feet figures: empty, not 0; a clean take: 0 skates and no largest.
    for key in ("unchecked", "older"):
        assert _feet(rows[ids[key]]) == (None,) * len(FEET_COLUMNS)
    assert _feet(rows[ids["clean"]]) == (0, None, None, 0, 0)

    by_worst = [r["take_id"] for r in store.page(shoot, 50, 0, "foot_worst_skate", True)[0]]
    bvh, trc = rows[ids["bvh"]]["foot_worst_skate"], rows[ids["trc"]]["foot_worst_skate"]
    larger, smaller = ("bvh", "trc") if bvh > trc else ("trc", "bvh")
    # Largest first, takes without a value last (by name) in either direction.
    assert by_worst == [ids[k] for k in (larger, smaller, "clean", "unchecked", "older")]
    by_worst = [r["take_id"] for r in store.page(shoot, 50, 0, "foot_worst_skate")[0]]
    assert by_worst == [ids[k] for k in (smaller, larger, "clean", "unchecked", "older")]
    by_count = [r["take_id"] for r in store.page(shoot, 2, 0, "foot_skates", True)[0]]
    assert set(by_count) == {ids["bvh"], ids["trc"]}
    assert store.page(shoot, 2, 2, "foot_skates", True)[0][0]["take_id"] == ids["clean"]

    some, total = store.page(shoot, 50, 0, "name", filters=TakeFilter(has_skates=True))
    assert ([r["take_id"] for r in some], total) == ([ids["bvh"], ids["trc"]], 2)
    none, total = store.page(shoot, 50, 0, "name", filters=TakeFilter(has_skates=False))
    assert ([r["take_id"] for r in none], total) == ([ids["clean"]], 1)
    assert TakeFilter(has_skates=False).chosen() == {"has_skates": False}


def test_migration_0010_fills_the_rows_of_runs_made_before_it(
    repository: Repository, analysed: dict[str, dict[str, Any]]
) -> None:
    store = ShootStore(repository.engine)
    shoot, ids = _shoot_of_five(store, analysed)
    before = {take_id: _row(repository, take_id) for take_id in ids.values()}
    downgrade_database(repository.engine, "0009")
    assert upgrade_database(repository.engine)[0] == f"migrated 0009 → {head_revision()}"
    for take_id, row in before.items():
        assert _row(repository, take_id) == row
    assert store.page(shoot, 50, 0, "foot_worst_skate", True)[0][0]["foot_skate_unit"] in (
        "cm", "% height",
    )  # fmt: skip
