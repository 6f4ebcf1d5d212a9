"""``mocapqa markers check``: the JSON contract, the tables, other formats and errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mocapqa.cli.main import main

TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


def test_the_json_object_keeps_the_fixed_contract(
    c3d_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = c3d_dir / "optitrack" / "kinematics_tennis_serve_nan.c3d"
    assert main(["markers", "check", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {"gaps", "swaps", "spikes", "segments", "static", "labels"} <= data.keys()
    assert data["swaps"] == []
    assert data["frames"] == 1092
    assert data["length_unit"] == "m"
    assert [(g["marker"], g["start"], g["end"]) for g in data["gaps"]][:2] == [
        ("Derrick:RSHO", 134, 147),
        ("Derrick:RSHO", 192, 195),
    ]
    for spike in data["spikes"]:
        assert 0 <= spike["start"] <= spike["peak"] <= spike["end"] < 1092
        assert spike["size_unit"] == "m/s^2"


def test_the_table_names_gaps_swaps_and_spikes(
    c3d_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = c3d_dir / "vicon" / "nick_freeform_001.c3d"
    assert main(["markers", "check", str(path)]) == 0
    out = capsys.readouterr().out
    for title in ("Gaps by marker", "Swaps", "Spikes", "Nick01:CLAV (absent)"):
        assert title in out


def test_a_trc_take_is_checked_too(corpus_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["markers", "check", str(corpus_dir / TRC), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["frames"] == 100
    assert data["length_unit"] == "m"
    assert data["gaps"] == []


def test_a_skeleton_or_a_missing_file_exits_3(
    cmu_walk: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["markers", "check", str(cmu_walk), "--json"]) == 3
    assert "Expected a marker or keypoint take" in capsys.readouterr().err
    assert main(["markers", "check", str(tmp_path / "none.c3d"), "--json"]) == 3
    empty = tmp_path / "empty.c3d"
    empty.write_bytes(b"")
    assert main(["markers", "check", str(empty), "--json"]) == 3


def test_an_analog_only_take_and_an_unnamed_trajectory(
    c3d_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["markers", "check", str(c3d_dir / "btk" / "1123x01EMG.c3d"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["markers"] == []
    assert data["gaps"] == data["swaps"] == data["spikes"] == []
    assert main(["markers", "check", str(c3d_dir / "btk" / "MotionMonitorC3D.c3d"), "--json"]) == 0
    labels = json.loads(capsys.readouterr().out)["labels"]
    assert labels == [{"kind": "unlabelled", "label": "*0", "markers": ["*0"],
                       "severity": "warning"}]  # fmt: skip


def test_fill_marks_every_filled_sample_and_changes_nothing_else(
    c3d_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`markers fill` on the real gapped take: the confident fills are written with residual 0
    and listed in the report, every other sample is as read, and the filled samples lie near
    the clean twin of the take (the same recording without its gaps)."""
    import ezc3d
    import numpy as np

    gapped = c3d_dir / "optitrack" / "kinematics_tennis_serve_nan.c3d"
    out, report = tmp_path / "filled.c3d", tmp_path / "report.json"
    assert main(["markers", "fill", str(gapped), "-o", str(out), "--report", str(report)]) == 0
    assert "gaps filled" in capsys.readouterr().out
    account = json.loads(report.read_text())
    applied = [g for g in account["gaps"] if g["applied"]]
    assert applied
    assert all(g["confident"] for g in applied)
    assert len(applied) < len(account["gaps"])  # the others are listed, not applied

    source, written = ezc3d.c3d(str(gapped)), ezc3d.c3d(str(out))
    clean = ezc3d.c3d(str(c3d_dir / "optitrack" / "kinematics_tennis_serve.c3d"))
    before = source["data"]["points"][:3]
    after = written["data"]["points"][:3]
    residual = written["data"]["meta_points"]["residuals"][0]
    seen = np.isfinite(before).all(axis=0) & (source["data"]["meta_points"]["residuals"][0] >= 0)
    assert np.array_equal(after[:, seen], before[:, seen])
    filled = ~seen & (residual >= 0)
    assert (
        filled.sum() == account["filled_samples"] == sum(g["end"] - g["start"] + 1 for g in applied)
    )
    assert np.all(residual[filled] == 0)
    assert np.all(residual[~seen & ~filled] < 0)  # gaps not applied stay missing (−1)
    error_m = np.linalg.norm(after[:, filled] - clean["data"]["points"][:3][:, filled], axis=0)
    assert float(np.sqrt(np.mean(error_m**2))) < 0.02  # metres; 11.6 mm measured

    none = tmp_path / "none.c3d"
    assert main(["markers", "fill", str(gapped), "-o", str(none), "--apply", "none"]) == 0
    unchanged = ezc3d.c3d(str(none))["data"]["meta_points"]["residuals"][0]
    assert np.array_equal(unchanged < 0, ~seen)
    assert main(["markers", "fill", str(gapped), "-o", str(none), "--apply", "most"]) == 3
    assert "--apply" in capsys.readouterr().err
