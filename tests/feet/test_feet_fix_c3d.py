"""``mocapqa feet fix`` on C3D marker takes: the foot markers of the locked side are pinned
during their contact and its blends, horizontally, and everything else in the file (other
markers, other frames, analogs, force plates) is written as read."""

from __future__ import annotations

import json
from pathlib import Path

import ezc3d
import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.feet.lock import BLEND_S
from mocapqa.io.c3d import read_c3d

PIG = "c3d/btk/PiG_Motion-FlatFoot-Full.c3d"  # Plug-in Gait, Z up, 100 fps, 2 force plates
NO_FEET = "c3d/btk/FP1.C3D"  # markers PT00-PT07


def test_a_c3d_take_has_the_locked_foot_s_markers_pinned_and_nothing_else_changed(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = corpus_dir / PIG
    assert main(["feet", "check", str(source), "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    assert check["up_axis"] == "Z"
    contact = next(c for c in check["contacts"] if c["foot"] == "left" and c["start"] > 0)
    none, pinned = tmp_path / "none.c3d", tmp_path / "pinned.c3d"
    assert main(["feet", "fix", str(source), "-o", str(none), "--apply", "none"]) == 0
    capsys.readouterr()
    args = ["feet", "fix", str(source), "-o", str(pinned), "--apply", contact["id"], "--json"]
    assert main(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["summary"]["contacts_locked"] == 1
    item = next(c for c in report["contacts"] if c["id"] == contact["id"])
    assert item["applied"] is True
    assert item["slide_after"] < item["slide_before"]

    raw, moved = read_c3d(none), read_c3d(pinned)
    names = raw.points.names
    before, after = raw.points.positions, moved.points.positions
    assert names == moved.points.names
    assert np.array_equal(np.isnan(before), np.isnan(after))
    # Written as read with nothing locked: only float32 rounding.
    original = read_c3d(source).points.positions
    np.testing.assert_allclose(before, original, rtol=2**-23, atol=1e-9, equal_nan=True)
    changed = ~np.all((before == after) | np.isnan(before), axis=2)  # (F, M)
    moved_markers = {names[m] for m in np.flatnonzero(changed.any(axis=0))}
    assert {"LHEE", "LTOE"} <= moved_markers <= {"LHEE", "LTOE", "LANK"}
    frames = np.flatnonzero(changed.any(axis=1))
    blend = round(BLEND_S * raw.points.fps)
    assert frames.min() >= contact["start"] - blend
    assert frames.max() <= contact["end"] + blend
    # Horizontally only: the up coordinate (Z) of every sample is as read.
    assert np.array_equal(before[..., 2], after[..., 2], equal_nan=True)
    assert np.array_equal(raw.residuals, moved.residuals)

    # Analogs bit for bit, force plates and events as they were.
    a, b = ezc3d.c3d(str(source)), ezc3d.c3d(str(pinned))
    assert np.array_equal(a["data"]["analogs"], b["data"]["analogs"])
    for group, key in (("FORCE_PLATFORM", "CORNERS"), ("EVENT", "TIMES")):
        assert np.array_equal(
            a["parameters"][group][key]["value"], b["parameters"][group][key]["value"]
        )


def test_a_c3d_take_without_foot_markers_exits_with_one_line(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out.c3d"
    assert main(["feet", "fix", str(corpus_dir / NO_FEET), "-o", str(out)]) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "Expected heel, toe or ankle markers" in err
    assert "PT00" in err
    assert not out.exists()
