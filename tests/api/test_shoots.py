"""Shoots through the API: lifecycle, imports (files and archives), table, heat map, queue,
export; real takes from the corpus."""

from __future__ import annotations

import csv
import gzip
import io
import tarfile
import time
import zipfile
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from tests.store.skating_take import drifted_bvh

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.render.service import RenderService

LEGACY = Path(__file__).resolve().parents[1] / "data" / "legacy"
API = "/api/v1"
WALK = "bvh/cmu/cmu_12_01_walk.bvh"
BANDAI = ("bvh/bandai/dataset-1_bow_not-confident_001.bvh", "bvh/bandai/dataset-1_bow_sad_001.bvh")
TRC = "keypoints/pose2sim/S00_P00_T00_StaticTrial/pose-3d/S00_P00_T00_StaticTrial_0-12.trc"


def _shoot(client: TestClient, name: str) -> dict[str, Any]:
    response = client.post(f"{API}/shoots", json={"name": name})
    assert response.status_code == 201, response.text
    body: dict[str, Any] = response.json()
    return body


def _wait_finished(client: TestClient, shoot_id: str, timeout_s: float = 120.0) -> dict[str, Any]:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        progress: dict[str, Any] = client.get(f"{API}/shoots/{shoot_id}/progress").json()
        if progress["finished"]:
            return progress
        time.sleep(0.1)
    raise TimeoutError("the shoot's analyses did not finish")


def _zip(members: list[tuple[str, bytes]], symlink: str | None = None) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members:
            archive.writestr(name, data)
        if symlink is not None:
            info = zipfile.ZipInfo(symlink)
            info.external_attr = (0o120777 << 16) | 0
            archive.writestr(info, "/etc/passwd")
    return buffer.getvalue()


def test_shoot_lifecycle(client: TestClient) -> None:
    shoot = _shoot(client, "Day 1")
    assert shoot["n_takes"] == 0
    assert shoot["status_counts"] == {"queued": 0, "running": 0, "done": 0, "failed": 0}
    assert client.post(f"{API}/shoots", json={"name": "Day 1"}).status_code == 409
    assert client.post(f"{API}/shoots", json={"name": ""}).status_code == 422
    renamed = client.patch(f"{API}/shoots/{shoot['id']}", json={"name": "Day one"})
    assert renamed.status_code == 200
    assert renamed.json()["name"] == "Day one"
    other = _shoot(client, "Day 2")
    taken = client.patch(f"{API}/shoots/{other['id']}", json={"name": "Day one"})
    assert taken.status_code == 409
    names = [s["name"] for s in client.get(f"{API}/shoots").json()]
    assert names == ["Day 2", "Day one"]
    assert client.get(f"{API}/shoots/{'0' * 32}").status_code == 404


def test_import_files_table_queue_export_and_delete(client: TestClient, corpus_dir: Path) -> None:
    shoot = _shoot(client, "walks")
    sid = shoot["id"]
    paths = [corpus_dir / WALK, *(corpus_dir / p for p in BANDAI), corpus_dir / TRC]
    handles = [p.open("rb") for p in paths]
    try:
        response = client.post(
            f"{API}/shoots/{sid}/takes",
            files=[("files", (p.name, h)) for p, h in zip(paths, handles, strict=True)],
        )
    finally:
        for handle in handles:
            handle.close()
    assert response.status_code == 201, response.text
    report = response.json()
    assert len(report["created"]) == 4
    assert report["failed"] == report["skipped"] == []
    progress = _wait_finished(client, sid)
    assert progress["status_counts"]["done"] == 4
    assert progress["frames_done"] == 524 + 145 + 221 + 12

    listed = client.get(f"{API}/shoots")
    assert listed.json()[0]["n_takes"] == 4
    page = client.get(f"{API}/shoots/{sid}/takes", params={"sort": "score"}).json()
    assert page["total"] == 4
    scores = [row["score"] for row in page["items"]]
    assert scores == sorted(scores)
    assert all(0 <= s <= 100 for s in scores)
    by_name = {row["name"]: row for row in page["items"]}
    assert by_name[Path(TRC).name]["rig"] == "keypoints"
    assert by_name[Path(TRC).name]["filter_residual_mm"] is not None
    assert by_name["cmu_12_01_walk.bvh"]["rig"] == "cmu"
    assert by_name["cmu_12_01_walk.bvh"]["violation_share"] is not None  # limits ran

    desc = client.get(f"{API}/shoots/{sid}/takes", params={"sort": "n_frames", "order": "desc"})
    assert [r["n_frames"] for r in desc.json()["items"]] == [524, 221, 145, 12]
    found = client.get(f"{API}/shoots/{sid}/takes", params={"search": "BOW", "rig": "bandai"})
    assert found.json()["total"] == 2
    ranged = client.get(f"{API}/shoots/{sid}/takes", params={"min_score": 101})
    assert ranged.status_code == 422
    crossed = {"min_score": 5, "max_score": 1}
    for route in ("takes", "heatmap", "summary.csv", "summary.json"):
        answer = client.get(f"{API}/shoots/{sid}/{route}", params=crossed)
        assert answer.status_code == 422, route
        assert answer.json()["field"] == "min_score"
    assert client.get(f"{API}/shoots/{sid}/takes", params={"sort": "nope"}).status_code == 422
    second = client.get(f"{API}/shoots/{sid}/takes", params={"limit": 2, "offset": 2}).json()
    assert [r["take_id"] for r in second["items"]] == [r["take_id"] for r in page["items"][2:]]

    heat = client.get(f"{API}/shoots/{sid}/heatmap").json()
    assert len(heat["takes"]) == 4
    assert len(heat["values"]) == len(heat["joints"])
    for joint, row in zip(heat["joints"], heat["values"], strict=True):
        for take, value in zip(heat["takes"], row, strict=True):
            expected = by_name[str(take["name"])]["joint_violations"] or {}
            assert value == expected.get(joint, 0.0 if value is not None else None)

    first = client.get(f"{API}/shoots/{sid}/next").json()
    assert first["remaining"] == 4
    assert first["take"]["take_id"] == page["items"][0]["take_id"]
    skipped = client.get(f"{API}/shoots/{sid}/next", params={"after": first["take"]["take_id"]})
    assert skipped.json()["take"]["take_id"] == page["items"][1]["take_id"]
    # Skipping again and again walks every waiting take in order, then comes round.
    order = [t["take_id"] for t in page["items"] if t["status"] == "done"]
    seen, at = [], None
    for _ in range(len(order) + 1):
        at = client.get(f"{API}/shoots/{sid}/next", params={"after": at} if at else {}).json()
        at = at["take"]["take_id"]
        seen.append(at)
    assert seen == [*order, order[0]]
    review = {"status": "approved", "reviewer": "lead"}
    posted = client.post(f"{API}/takes/{first['take']['take_id']}/reviews", json=review)
    assert posted.status_code == 201, posted.text
    after = client.get(f"{API}/shoots/{sid}/next").json()
    assert after["remaining"] == 3
    assert after["take"]["take_id"] == page["items"][1]["take_id"]

    exported = client.get(f"{API}/shoots/{sid}/summary.csv")
    assert exported.status_code == 200
    assert exported.headers["content-type"].startswith("text/csv")
    rows = list(csv.DictReader(io.StringIO(exported.text)))
    assert sorted(r["name"] for r in rows) == sorted(p.name for p in paths)
    approved = [r for r in rows if r["review_status"] == "approved"]
    assert len(approved) == 1
    # The reviewer is who is signed in (anonymous on a server without users), never the body's.
    assert approved[0]["reviewer"] == "anonymous"
    as_json = client.get(f"{API}/shoots/{sid}/summary.json").json()
    assert as_json["shoot"] == "walks"
    assert {t["name"]: t["score"] for t in as_json["takes"]} == {
        r["name"]: float(r["score"]) for r in rows
    }
    # With the take table's filters and order (what the dashboard's links send), the export
    # holds the table's takes in the table's order, and says which filters it applied.
    chosen = {"review_status": "approved"}
    only = list(csv.DictReader(io.StringIO(
        client.get(f"{API}/shoots/{sid}/summary.csv", params=chosen).text)))  # fmt: skip
    assert [r["name"] for r in only] == [r["name"] for r in approved]
    ordered = {"sort": "score", "order": "desc", "has_findings": "false"}
    table = client.get(f"{API}/shoots/{sid}/takes", params=ordered).json()["items"]
    as_json = client.get(f"{API}/shoots/{sid}/summary.json", params=ordered).json()
    assert [t["name"] for t in as_json["takes"]] == [t["name"] for t in table]
    assert as_json["filters"] == {"has_findings": False}
    assert (as_json["sort"], as_json["order"]) == ("score", "desc")
    # A take named like a formula is text in the CSV, whatever a spreadsheet makes of it.
    named = client.post(
        f"{API}/shoots/{sid}/takes",
        files=[("files", ("=HYPERLINK(1).bvh", (paths[0]).read_bytes()))],
    )
    assert named.status_code == 201, named.text
    cells = list(csv.DictReader(io.StringIO(client.get(f"{API}/shoots/{sid}/summary.csv").text)))
    formula = [r["name"] for r in cells if "HYPERLINK" in r["name"]]
    assert formula
    assert all(n.startswith("'=") for n in formula)
    bad = client.get(f"{API}/shoots/{sid}/summary.csv", params={"min_score": 500})
    assert bad.status_code == 422
    assert "min_score" in bad.text

    refused = client.delete(f"{API}/shoots/{sid}")
    assert refused.status_code == 422
    assert client.get(f"{API}/shoots/{sid}").status_code == 200
    gone = client.delete(f"{API}/shoots/{sid}", params={"confirm": "walks"})
    assert gone.status_code == 204
    assert client.get(f"{API}/shoots/{sid}").status_code == 404
    assert client.get(f"{API}/takes").json()["total"] == 0


def test_zip_import_keeps_good_members(client: TestClient, corpus_dir: Path) -> None:
    sid = _shoot(client, "archive")["id"]
    walk = (corpus_dir / WALK).read_bytes()
    bandai = (corpus_dir / BANDAI[0]).read_bytes()
    corrupted = walk[: len(walk) // 3].replace(b"Frames: 524", b"Frames: 9999")
    archive = _zip(
        [
            ("day/walk.bvh", walk),
            ("day/sub/bow.bvh", bandai),
            ("day/broken.bvh", corrupted),
            ("day/notes.txt", b"call sheet"),
            ("../../escape.bvh", bandai),
            ("/abs/escape.bvh", bandai),
        ],
        symlink="day/link.bvh",
    )
    response = client.post(f"{API}/shoots/{sid}/takes", files=[("files", ("day.zip", archive))])
    assert response.status_code == 201, response.text
    report = response.json()
    assert sorted(c["name"] for c in report["created"]) == ["bow.bvh", "walk.bvh"]
    assert [s["name"] for s in report["skipped"]] == ["day.zip:day/notes.txt"]
    failed = {f["name"]: f["error"] for f in report["failed"]}
    assert set(failed) == {
        "day.zip:day/broken.bvh",
        "day.zip:../../escape.bvh",
        "day.zip:/abs/escape.bvh",
        "day.zip:day/link.bvh",
    }
    assert "line" in failed["day.zip:day/broken.bvh"]
    assert "symbolic link" in failed["day.zip:day/link.bvh"]
    assert "'..'" in failed["day.zip:../../escape.bvh"]
    data_dir = client.app.state.services.settings.data_dir  # type: ignore[attr-defined]
    assert not (data_dir.parent / "escape.bvh").exists()
    assert not list(data_dir.rglob("escape.bvh"))
    progress = _wait_finished(client, sid)
    assert progress["status_counts"]["done"] == 2, (progress, client.get(f"{API}/takes").json())


def test_import_skips_keypoint_csv_sidecars(client: TestClient) -> None:
    """A ``.meta.json`` beside its CSV is the CSV's metadata, not a take (batches skip it too)."""
    sid = _shoot(client, "sidecars")["id"]
    meta = b'{"fps": 30.0, "length_unit": "m"}'
    response = client.post(
        f"{API}/shoots/{sid}/takes",
        files=[
            ("files", ("day.zip", _zip([("day/kp.csv.meta.json", meta)]))),
            ("files", ("walk.CSV.meta.json", meta)),
        ],
    )
    assert response.status_code == 201, response.text
    report = response.json()
    assert report["created"] == []
    assert report["failed"] == []
    assert [s["name"] for s in report["skipped"]] == [
        "day.zip:day/kp.csv.meta.json",
        "walk.CSV.meta.json",
    ]
    assert all("sidecar" in s["reason"] for s in report["skipped"])
    # An import stores each file as a take of its own: the sidecar is not read, and says so.
    assert all("not read by an import" in s["reason"] for s in report["skipped"])


def test_tar_import_reports_links(client: TestClient, corpus_dir: Path) -> None:
    sid = _shoot(client, "tarred")["id"]
    buffer = io.BytesIO()
    bandai = (corpus_dir / BANDAI[1]).read_bytes()
    with tarfile.open(fileobj=buffer, mode="w:gz") as archive:
        info = tarfile.TarInfo("takes/sad.bvh")
        info.size = len(bandai)
        archive.addfile(info, io.BytesIO(bandai))
        for kind, name in (
            (tarfile.SYMTYPE, "takes/soft.bvh"),
            (tarfile.LNKTYPE, "takes/hard.bvh"),
        ):
            link = tarfile.TarInfo(name)
            link.type = kind
            link.linkname = "/etc/passwd"
            archive.addfile(link)
    response = client.post(
        f"{API}/shoots/{sid}/takes", files=[("files", ("takes.tar.gz", buffer.getvalue()))]
    )
    assert response.status_code == 201, response.text
    report = response.json()
    assert [c["name"] for c in report["created"]] == ["sad.bvh"]
    failed = {f["name"]: f["error"] for f in report["failed"]}
    assert failed == {
        "takes.tar.gz:takes/soft.bvh": "symbolic link",
        "takes.tar.gz:takes/hard.bvh": "hard link",
    }
    # An unreadable archive is listed as failed, naming it; the other files of the request
    # are imported as usual (it used to fail the request after storing the files before it).
    bandai_walk = (corpus_dir / BANDAI[0]).read_bytes()
    garbage = client.post(
        f"{API}/shoots/{sid}/takes",
        files=[
            ("files", ("bad.tar.gz", b"not a tar at all")),
            ("files", ("walk.bvh", bandai_walk)),
            ("files", ("readme.txt", b"notes beside the takes")),
        ],
    )
    assert garbage.status_code == 201, garbage.text
    # The same walk again: kept (a reviewer may want both) and said to be a copy.
    again = client.post(f"{API}/shoots/{sid}/takes", files=[("files", ("copy.bvh", bandai_walk))])
    assert again.json()["created"][0]["duplicate_of"] == "walk.bvh"
    assert "duplicate_of" not in garbage.json()["created"][0]
    # A loose text file is skipped like an archive member of its kind, not a failed take.
    assert garbage.json()["skipped"] == [{"name": "readme.txt", "reason": "not a motion file"}]
    failed = {f["name"]: f["error"] for f in garbage.json()["failed"]}
    assert "readable .tar.gz" in failed["bad.tar.gz"]
    assert [c["name"] for c in garbage.json()["created"]] == ["walk.bvh"]


def test_archive_bombs_are_refused_before_extracting(
    tmp_path: Path, renderer: RenderService, corpus_dir: Path
) -> None:
    settings = Settings(
        allowed_hosts=["testserver"],
        data_dir=tmp_path / "data",
        archive_max_unpacked_mb=1.0,
        archive_max_members=3,
    )
    with TestClient(create_app(settings, renderer=renderer)) as client:
        sid = _shoot(client, "bombs")["id"]
        bomb = _zip([("zeros.bvh", bytes(20_000_000))])
        assert len(bomb) < 100_000
        response = client.post(f"{API}/shoots/{sid}/takes", files=[("files", ("b.zip", bomb))])
        assert response.status_code == 413
        assert "20000000 declared" in response.json()["detail"]
        bandai = (corpus_dir / BANDAI[0]).read_bytes()
        many = _zip([(f"t{i}.bvh", bandai) for i in range(4)])
        response = client.post(f"{API}/shoots/{sid}/takes", files=[("files", ("m.zip", many))])
        assert response.status_code == 413
        assert "at most 3 members" in response.json()["detail"]
        # A 1.5 GB GNU long name (tarfile would read it whole into memory) in a .tar.gz of a
        # few MB is refused from its header, before tarfile opens the archive.
        declared = 1_500_000_000
        info = tarfile.TarInfo("././@LongLink").get_info()
        info.update(size=declared, type=tarfile.GNUTYPE_LONGNAME)
        header = tarfile.TarInfo._create_header(  # type: ignore[attr-defined]
            info, tarfile.GNU_FORMAT, "utf-8", "surrogateescape"
        )
        packed = io.BytesIO()
        with gzip.GzipFile(fileobj=packed, mode="wb", compresslevel=9) as out:
            out.write(header)
            for _ in range(8):
                out.write(b"a" * (1 << 20))
        response = client.post(
            f"{API}/shoots/{sid}/takes", files=[("files", ("n.tar.gz", packed.getvalue()))]
        )
        assert response.status_code == 413, response.text
        assert f"at most 65536 bytes, got one of {declared}" in response.json()["detail"]
        assert client.get(f"{API}/shoots/{sid}").json()["n_takes"] == 0
        assert not list((settings.data_dir / "incoming").iterdir())


def test_openapi_declares_shoot_statuses(client: TestClient) -> None:
    paths = client.get("/openapi.json").json()["paths"]
    delete = paths[f"{API}/shoots/{{shoot_id}}"]["delete"]["responses"]
    assert {"204", "404", "422"} <= set(delete)
    imports = paths[f"{API}/shoots/{{shoot_id}}/takes"]["post"]["responses"]
    assert {"201", "404", "413", "422"} <= set(imports)


@pytest.mark.parametrize("kind", ["sqlite"])
def test_database_from_before_shoots_opens(kind: str, tmp_path: Path) -> None:
    """A database made by the first release (tests/data/legacy) takes shoots once opened."""
    import shutil

    from mocapqa.store.repository import Repository
    from mocapqa.store.shoots import ShootStore

    path = tmp_path / "old.sqlite3"
    shutil.copyfile(LEGACY / "228f57d.sqlite3", path)
    repository = Repository(f"sqlite:///{path}")
    try:
        items, total = repository.list_takes()
        assert total == 2
        take = min(items, key=lambda t: str(t["name"]))
        assert take["shoot_id"] is None
        store = ShootStore(repository.engine)
        shoot = store.create("old")
        store.assign(str(take["id"]), str(shoot["id"]))
        rows, total = store.page(str(shoot["id"]))
        assert total == 1
        assert rows[0]["n_frames"] == take["n_frames"] == 24
    finally:
        repository.close()


def test_demo_shoot_beside_the_single_takes(tmp_path: Path, renderer: RenderService) -> None:
    from mocapqa.jobs.demo import DEMO_FILES, DEMO_SHOOT, DEMO_SHOOT_CORPUS_FILES

    settings = Settings(allowed_hosts=["testserver"], data_dir=tmp_path / "data")
    with TestClient(create_app(settings, demo=True, renderer=renderer)) as client:
        shoots = client.get(f"{API}/shoots").json()
        assert [s["name"] for s in shoots] == [DEMO_SHOOT]
        n_shoot = len(DEMO_FILES) + len(DEMO_SHOOT_CORPUS_FILES)
        assert shoots[0]["status_counts"]["done"] == shoots[0]["n_takes"] == n_shoot
        assert client.get(f"{API}/takes").json()["total"] == len(DEMO_FILES) + n_shoot


BALANCING_TRC = (
    "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
)
"""A keypoint take in metres with a skate (sized in cm)."""
CLEAN_BVH = "bvh/bandai/dataset-1_dash_normal_001.bvh"  # feet checked, nothing found
FEET = (
    "foot_skates",
    "foot_worst_skate",
    "foot_skate_unit",
    "foot_penetrations",
    "foot_floating",
    "foot_worst_skate_pct",
)


def test_the_take_table_sorts_filters_and_exports_the_feet_figures(
    client: TestClient, corpus_dir: Path, tmp_path: Path
) -> None:
    sid = _shoot(client, "feet")["id"]
    skating = drifted_bvh(corpus_dir, tmp_path)
    paths = [skating, corpus_dir / BALANCING_TRC, corpus_dir / CLEAN_BVH]
    response = client.post(
        f"{API}/shoots/{sid}/takes", files=[("files", (p.name, p.read_bytes())) for p in paths]
    )
    assert response.status_code == 201, response.text
    assert _wait_finished(client, sid)["status_counts"]["done"] == 3
    by_worst = {"sort": "foot_worst_skate", "order": "desc"}
    rows = client.get(f"{API}/shoots/{sid}/takes", params=by_worst).json()["items"]
    by_name = {r["name"]: r for r in rows}
    bvh, trc, clean = (by_name[p.name] for p in paths)
    assert bvh["foot_skates"] >= 1
    assert bvh["foot_skate_unit"] == "% height"
    assert trc["foot_skates"] >= 1
    assert trc["foot_skate_unit"] == "cm"
    assert (clean["foot_skates"], clean["foot_worst_skate"], clean["foot_skate_unit"]) == (
        0, None, None,
    )  # fmt: skip
    # Largest first in % of the body height, the one measure of every take (cm and % height
    # are not compared as numbers); a BVH's largest skate is in % height already. Takes
    # without the share (no skate) last, by name.
    assert bvh["foot_worst_skate_pct"] == bvh["foot_worst_skate"]
    shared = sorted(
        (r for r in (bvh, trc) if r["foot_worst_skate_pct"] is not None),
        key=lambda r: -float(r["foot_worst_skate_pct"]),
    )
    assert [r["name"] for r in rows[: len(shared)]] == [r["name"] for r in shared]
    assert rows[-1]["name"] == clean["name"]
    assert clean["foot_worst_skate_pct"] is None
    by_share = {"sort": "foot_worst_skate_pct", "order": "desc"}
    again = client.get(f"{API}/shoots/{sid}/takes", params=by_share).json()["items"]
    assert [r["name"] for r in again] == [r["name"] for r in rows]
    # The figures are the run's own findings (what the take view lists).
    for row in (bvh, trc):
        findings = client.get(f"{API}/runs/{row['run_id']}/result").json()["findings"]
        skates = [f for f in findings if f["kind"] == "skate"]
        assert row["foot_skates"] == len(skates)
        assert row["foot_worst_skate"] == max(f["value"] for f in skates)
        assert {f["unit"] for f in skates} == {row["foot_skate_unit"]}
        assert row["foot_penetrations"] == sum(f["kind"] == "penetration" for f in findings)
    for sort in ("foot_skates", "foot_penetrations", "foot_floating"):
        answer = client.get(f"{API}/shoots/{sid}/takes", params={"sort": sort, "order": "desc"})
        assert answer.status_code == 200, answer.text
        values = [r[sort] for r in answer.json()["items"]]
        assert values == sorted(values, reverse=True)
    skating = client.get(f"{API}/shoots/{sid}/takes", params={"has_skates": "true"}).json()
    assert sorted(r["name"] for r in skating["items"]) == sorted((bvh["name"], trc["name"]))
    none = client.get(f"{API}/shoots/{sid}/takes", params={"has_skates": "false"}).json()
    assert [r["name"] for r in none["items"]] == [clean["name"]]
    assert client.get(f"{API}/shoots/{sid}/takes", params={"has_skates": "x"}).status_code == 422

    exported = list(csv.DictReader(io.StringIO(client.get(f"{API}/shoots/{sid}/summary.csv").text)))
    cells = {r["name"]: r for r in exported}
    assert cells[bvh["name"]]["foot_skate_unit"] == "% height"
    assert float(cells[trc["name"]]["foot_worst_skate"]) == trc["foot_worst_skate"]
    assert cells[clean["name"]]["foot_worst_skate"] == ""
    assert float(cells[bvh["name"]]["foot_worst_skate_pct"]) == bvh["foot_worst_skate_pct"]
    as_json = client.get(f"{API}/shoots/{sid}/summary.json", params={"has_skates": "true"}).json()
    assert as_json["filters"] == {"has_skates": True}
    assert {t["name"]: tuple(t[k] for k in FEET) for t in as_json["takes"]} == {
        r["name"]: tuple(r[k] for k in FEET) for r in (bvh, trc)
    }

    # A run that does not check the feet leaves the figures empty, not 0.
    again = client.post(f"{API}/takes/{bvh['take_id']}/runs", json={"checks": ["twist", "limits"]})
    assert again.status_code == 201, again.text
    _wait_finished(client, sid)
    rows = client.get(f"{API}/shoots/{sid}/takes", params={"sort": "foot_skates"}).json()["items"]
    assert [r["name"] for r in rows][-1] == bvh["name"]  # no value: last
    assert all(rows[-1][k] is None for k in FEET)
