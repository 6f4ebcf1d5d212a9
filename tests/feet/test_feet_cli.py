"""``mocapqa feet check``: the JSON contract, the tables, units and errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mocapqa.cli.main import main

TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


def run_json(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, object]:
    assert main(["feet", "check", *args, "--json"]) == 0
    return dict(json.loads(capsys.readouterr().out))


def test_the_json_object_keeps_the_fixed_contract(
    cmu_walk: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = run_json(capsys, str(cmu_walk))
    assert data["up_axis"] == "Y"
    assert isinstance(data["floor"], float)
    contacts = data["contacts"]
    assert isinstance(contacts, list)
    assert len(contacts) == 8
    for contact in contacts:
        assert contact["foot"] in ("left", "right")
        assert 0 <= contact["start"] <= contact["end"] < 524  # 0-based, ends inclusive
    assert data["findings"] == []


def test_findings_carry_frames_and_a_size_in_cm(
    corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = run_json(capsys, str(corpus_dir / TRC))
    assert data["cm_per_unit"] == 100.0
    findings = data["findings"]
    assert isinstance(findings, list)
    assert findings
    for finding in findings:
        assert finding["kind"] in ("skate", "penetration", "floating", "jitter")
        assert finding["foot"] in ("left", "right")
        assert 0 <= finding["start"] <= finding["end"] < 100
        assert finding["size_cm"] == pytest.approx(100.0 * finding["size"], abs=1e-3)


def test_a_told_length_unit_turns_a_bvh_take_s_sizes_into_cm(
    cmu_walk: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = run_json(capsys, str(cmu_walk), "--length-unit", "in")
    assert data["cm_per_unit"] == 2.54
    assert data["leg_length_cm"] == pytest.approx(13.9274 * 2.54, abs=1e-3)
    assert data["sizes"] == "cm"


def test_the_table_names_the_floor_and_the_contacts(
    cmu_walk: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["feet", "check", str(cmu_walk)]) == 0
    out = capsys.readouterr().out
    assert "up axis" in out
    assert "Y (feet and body)" in out
    assert "frame 0 is a bind pose" in out
    assert "113–191" in out  # the second left contact


def test_a_rig_without_legs_exits_with_the_input_error_code(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    take = tmp_path / "spine.bvh"
    take.write_text(
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n"
        " JOINT Spine\n {\n  OFFSET 0 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
        "  End Site\n  {\n   OFFSET 0 10 0\n  }\n }\n}\nMOTION\nFrames: 3\n"
        "Frame Time: 0.04\n0 0 0 0 0 0\n0 0 0 0 0 0\n0 0 0 0 0 0\n",
        encoding="utf-8",
    )
    assert main(["feet", "check", str(take), "--json"]) == 3
    assert "Expected a rig with upper leg, lower leg and foot joints" in capsys.readouterr().err


def test_a_bad_length_unit_and_a_mapping_for_keypoints_are_input_errors(
    cmu_walk: Path, corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["feet", "check", str(cmu_walk), "--length-unit", "furlong"]) == 3
    assert "Expected --length-unit among" in capsys.readouterr().err
    mapping = tmp_path / "map.json"
    mapping.write_text(json.dumps({"left_foot": "LeftFoot"}), encoding="utf-8")
    assert main(["feet", "check", str(corpus_dir / TRC), "--mapping", str(mapping)]) == 3
    assert "Expected --mapping only for a BVH take" in capsys.readouterr().err


def test_a_missing_file_is_an_input_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["feet", "check", str(tmp_path / "none.bvh")]) == 3
    assert "none.bvh" in capsys.readouterr().err
