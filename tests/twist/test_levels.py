"""Rebuilding a corrected take from the raw one and the reported levels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.levels import remove_levels


def test_the_reported_levels_rebuild_each_apply_choice(corpus_dir: Path) -> None:
    raw = read_bvh(corpus_dir / "bvh" / "cmu" / "iclone" / "005_05.bvh")
    for apply in ("confident", "all", "none"):
        analysis = analyze_twist(raw, apply=apply)
        levels: dict[str, list[tuple[int, int, float]]] = {}
        for interval in analysis.intervals:
            if interval.applied:
                # As the report holds them (degrees, rounded to 1e-6).
                levels.setdefault(interval.joint, []).extend(
                    (a, b, round(v, 6)) for a, b, v in interval.levels
                )
        rebuilt = remove_levels(raw, levels)
        np.testing.assert_allclose(rebuilt.quats, analysis.refined.quats, atol=1e-7)
        assert (rebuilt is raw) == (not levels)
    assert any(i.applied for i in analyze_twist(raw).intervals)


def test_a_level_must_name_a_chain_and_fit_the_take(corpus_dir: Path) -> None:
    raw = read_bvh(corpus_dir / "bvh" / "cmu" / "iclone" / "005_05.bvh")
    with pytest.raises(InputError, match="limb chain"):
        remove_levels(raw, {"CC_Base_Hip": [(0, 1, 10.0)]})
    with pytest.raises(InputError, match="within frames"):
        remove_levels(raw, {"CC_Base_L_Calf": [(0, raw.n_frames, 10.0)]})
