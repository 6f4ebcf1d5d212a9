"""The BVH root position reading, with its reason, in ``info`` and reports, and its override."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.cli.report import analyze_take
from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.forward import forward_kinematics


def info(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, object]:
    assert main(["info", *args, "--json"]) == 0
    return dict(json.loads(capsys.readouterr().out))


def test_info_says_which_root_reading_and_why(
    corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cc = str(corpus_dir / "bvh" / "cmu" / "iclone" / "001_14.bvh")
    detected = info(capsys, cc)
    assert detected["root_translation"] == "add"
    reason = str(detected["root_translation_reason"])
    assert reason.startswith("add (detected): the root's Y channel has median |value|")
    assert "Blender's importer takes them as absolute positions" in reason
    forced = info(capsys, cc, "--root-translation", "replace")
    assert forced["root_translation"] == "replace"
    assert str(forced["root_translation_reason"]).startswith("replace (chosen by the user)")
    walk = info(capsys, str(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh"))
    assert str(walk["root_translation_reason"]).startswith("replace: the root OFFSET is zero")
    assert main(["info", cc, "--root-translation", "sideways"]) != 0


def test_the_two_readings_differ_by_the_root_offset(corpus_dir: Path) -> None:
    # Blender's reading (replace) puts the CC body one root OFFSET (105.2 units) lower.
    path = corpus_dir / "bvh" / "cmu" / "iclone" / "001_14.bvh"
    _, added = forward_kinematics(read_bvh(path, root_translation="add"))
    _, replaced = forward_kinematics(read_bvh(path, root_translation="replace"))
    np.testing.assert_allclose(added[..., 1] - replaced[..., 1], 105.214226, atol=1e-6)
    np.testing.assert_allclose(added[..., [0, 2]] - replaced[..., [0, 2]], 0.0, atol=1e-4)


def test_a_report_run_records_the_reading(corpus_dir: Path) -> None:
    path = corpus_dir / "bvh" / "cmu" / "iclone" / "001_14.bvh"
    run = analyze_take(path, {"checks": ["twist"], "max_points": 50}, None, "replace")
    summary = run.analysis["summary"]
    assert summary["root_translation"] == "replace"
    assert summary["root_translation_reason"].startswith("replace (chosen by the user)")
    assert summary["missing_roles"] == []
