"""The feet figures of a take's row on SQLite and PostgreSQL: skate, penetration and floating
counts, the largest skate with its unit and in % of the body height, from real analyses of a
BVH take given a slide and a TRC take with a skate (the same figures as ``mocapqa feet
check``); sorted (the largest skate by its % of the body height, whatever the take's unit) and
filtered in the shoot table, empty (not 0) for a run that did not check the feet, and filled by
migrations 0010 and 0012 from the summaries runs made before them."""

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
from mocapqa.pipeline.summary import skate_pct_height
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
        if unit == "% height":  # in % of the body height already: the same figure
            assert row["foot_worst_skate_pct"] == row["foot_worst_skate"]
        for column, kind in (("foot_penetrations", "penetration"), ("foot_floating", "floating")):
            assert row[column] == sum(f["kind"] == kind for f in check["findings"])
        # The row written with the take is the one the store rebuilds.
        with repository.engine.begin() as conn:
            sync_take(conn, take_id)
        assert _row(repository, take_id) == row


def test_a_skate_s_share_of_the_body_height_is_the_same_measure_in_every_take(
    folders: dict[str, Path],
) -> None:
    """A % height skate's value; a cm skate's ``size_rel_height`` (the feet check's) × 100;
    nothing for a cm skate without it: a number in cm is never read as a share."""
    check = _feet_check(folders[TRC], TRC)
    skates = [f for f in check["findings"] if f["kind"] == "skate"]
    assert skates
    for f in skates:
        finding = {"kind": "skate", "foot": f["foot"], "value": f["size_cm"], "unit": "cm"}
        assert skate_pct_height(finding) is None
        share = skate_pct_height({**finding, "size_rel_height": f["size_rel_height"]})
        assert share == pytest.approx(100 * f["size_rel_height"], abs=1e-3)
        # The share and the size agree through the check's body height estimate (cm).
        height_cm = check["body_height_estimate"] * check["cm_per_unit"]
        assert share == pytest.approx(100 * f["size_cm"] / height_cm, rel=1e-3)
    assert skate_pct_height({"kind": "skate", "value": 2.217, "unit": "% height"}) == 2.217
    assert skate_pct_height({"kind": "skate", "value": None, "unit": "% height"}) is None


def _with_share(outcome: dict[str, Any], check: dict[str, Any]) -> dict[str, Any]:
    """A TRC take's analysis, checked: its summary has its largest skate in % of the body
    height, the feet check's largest ``size_rel_height`` of its skates (its findings carry it)."""
    shares = [100 * f["size_rel_height"] for f in check["findings"] if f["kind"] == "skate"]
    found = outcome["summary"]["qa"]["foot_worst_skate_pct"]
    assert found == pytest.approx(max(shares), abs=1e-3)
    return outcome


def _shoot_of_five(
    store: ShootStore, analysed: dict[str, dict[str, Any]], trc: dict[str, Any]
) -> tuple[str, dict[str, str]]:
    """A shoot with the BVH and TRC (``trc``) takes, a BVH take whose skate is larger in % of
    the height than the TRC's but smaller as a number than its size in cm, a clean take (feet
    checked, no skate), a take whose run did not check the feet and one whose run was made
    before the feet figures."""
    shoot = str(store.create("five")["id"])
    bvh_qa = analysed[BVH]["summary"]["qa"]
    assert bvh_qa["foot_worst_skate"] < trc["summary"]["qa"]["foot_worst_skate_pct"]
    larger = copy.deepcopy(analysed[BVH])
    share = (
        trc["summary"]["qa"]["foot_worst_skate_pct"] + trc["summary"]["qa"]["foot_worst_skate"]
    ) / 2
    larger["summary"]["qa"].update(foot_worst_skate=share, foot_worst_skate_pct=share)
    clean = copy.deepcopy(analysed[BVH])
    clean["summary"]["qa"].update(foot_skates=0, foot_worst_skate=None, foot_skate_unit=None,
                                  foot_penetrations=0, foot_floating=0,
                                  foot_worst_skate_pct=None)  # fmt: skip
    unchecked = copy.deepcopy(analysed[BVH])
    unchecked["summary"]["qa"].update(dict.fromkeys(FEET_COLUMNS))
    older = copy.deepcopy(analysed[BVH])
    for column in (*FEET_COLUMNS, "foot_contacts", "foot_jitter"):
        del older["summary"]["qa"][column]
    names = {
        "bvh": (analysed[BVH], "a_bvh.bvh"),
        "trc": (trc, "b_trc.trc"),
        "larger": (larger, "b_larger.bvh"),
        "clean": (clean, "c_clean.bvh"),
        "unchecked": (unchecked, "d_unchecked.bvh"),
        "older": (older, "e_older.bvh"),
    }
    return shoot, {key: _record(store, shoot, *value) for key, value in names.items()}


def test_the_shoot_table_sorts_and_filters_by_the_feet_figures(
    repository: Repository, folders: dict[str, Path], analysed: dict[str, dict[str, Any]]
) -> None:
    store = ShootStore(repository.engine)
    trc = _with_share(analysed[TRC], _feet_check(folders[TRC], TRC))
    shoot, ids = _shoot_of_five(store, analysed, trc)
    rows = {r["take_id"]: r for r in store.page(shoot, 50)[0]}
    # No feet figures: empty, not 0; a clean take: 0 skates and no largest.
    for key in ("unchecked", "older"):
        assert _feet(rows[ids[key]]) == (None,) * len(FEET_COLUMNS)
    assert _feet(rows[ids["clean"]]) == (0, None, None, 0, 0, None)
    # The TRC's largest skate in cm is the largest number, its share of the height is not.
    worst = {k: rows[ids[k]]["foot_worst_skate"] for k in ("bvh", "trc", "larger")}
    assert max(worst, key=lambda k: worst[k]) == "trc"
    assert rows[ids["trc"]]["foot_skate_unit"] == "cm"
    shares = {k: rows[ids[k]]["foot_worst_skate_pct"] for k in ("bvh", "trc", "larger")}
    assert shares["bvh"] < shares["trc"] < shares["larger"]

    # Largest share of the height first, takes without a value last (by name) either way.
    by_worst = [r["take_id"] for r in store.page(shoot, 50, 0, "foot_worst_skate", True)[0]]
    rest = ("clean", "unchecked", "older")
    assert by_worst == [ids[k] for k in ("larger", "trc", "bvh", *rest)]
    by_worst = [r["take_id"] for r in store.page(shoot, 50, 0, "foot_worst_skate")[0]]
    assert by_worst == [ids[k] for k in ("bvh", "trc", "larger", *rest)]
    by_share = [r["take_id"] for r in store.page(shoot, 50, 0, "foot_worst_skate_pct", True)[0]]
    assert by_share == [ids[k] for k in ("larger", "trc", "bvh", *rest)]
    by_count = [r["take_id"] for r in store.page(shoot, 3, 0, "foot_skates", True)[0]]
    assert set(by_count) == {ids["bvh"], ids["trc"], ids["larger"]}
    assert store.page(shoot, 3, 3, "foot_skates", True)[0][0]["take_id"] == ids["clean"]

    some, total = store.page(shoot, 50, 0, "name", filters=TakeFilter(has_skates=True))
    assert ([r["take_id"] for r in some], total) == ([ids[k] for k in ("bvh", "larger", "trc")], 3)
    none, total = store.page(shoot, 50, 0, "name", filters=TakeFilter(has_skates=False))
    assert ([r["take_id"] for r in none], total) == ([ids["clean"]], 1)
    assert TakeFilter(has_skates=False).chosen() == {"has_skates": False}


def test_migration_0010_fills_the_rows_of_runs_made_before_it(
    repository: Repository, folders: dict[str, Path], analysed: dict[str, dict[str, Any]]
) -> None:
    store = ShootStore(repository.engine)
    trc = _with_share(analysed[TRC], _feet_check(folders[TRC], TRC))
    shoot, ids = _shoot_of_five(store, analysed, trc)
    before = {take_id: _row(repository, take_id) for take_id in ids.values()}
    downgrade_database(repository.engine, "0009")
    assert upgrade_database(repository.engine)[0] == f"migrated 0009 → {head_revision()}"
    for take_id, row in before.items():
        assert _row(repository, take_id) == row
    assert store.page(shoot, 50, 0, "foot_worst_skate", True)[0][0]["foot_skate_unit"] in (
        "cm", "% height",
    )  # fmt: skip


def test_migration_0012_gives_rows_the_largest_skate_in_pct_of_the_height(
    repository: Repository, folders: dict[str, Path], analysed: dict[str, dict[str, Any]]
) -> None:
    """Rows of runs that have the share take it; rows of runs made before it take their largest
    skate when it is in % height already, and stay empty when it is in cm: as the store
    rebuilds them."""
    store = ShootStore(repository.engine)
    shoot, ids = _shoot_of_five(
        store, analysed, _with_share(analysed[TRC], _feet_check(folders[TRC], TRC))
    )
    made_before = {}
    for key, outcome, name in (
        ("bvh", analysed[BVH], "f_bvh.bvh"),
        ("trc", analysed[TRC], "g_trc.trc"),
    ):
        older = copy.deepcopy(outcome)
        del older["summary"]["qa"]["foot_worst_skate_pct"]
        made_before[key] = _record(store, shoot, older, name)
    before = {
        take_id: _row(repository, take_id) for take_id in (*ids.values(), *made_before.values())
    }
    assert (
        before[made_before["bvh"]]["foot_worst_skate_pct"] == before[ids["bvh"]]["foot_worst_skate"]
    )
    assert before[made_before["trc"]]["foot_worst_skate_pct"] is None
    assert before[ids["trc"]]["foot_worst_skate_pct"] is not None

    downgrade_database(repository.engine, "0011")
    with repository.engine.connect() as conn:
        columns = conn.exec_driver_sql("SELECT * FROM take_qa").keys()
        assert "foot_worst_skate_pct" not in list(columns)
    assert upgrade_database(repository.engine)[0] == f"migrated 0011 → {head_revision()}"
    for take_id, row in before.items():
        assert _row(repository, take_id) == row
        with repository.engine.begin() as conn:
            sync_take(conn, take_id)
        assert _row(repository, take_id) == row
