"""``mocapqa render`` end to end on a real take."""

from __future__ import annotations

from pathlib import Path

import pytest

from mocapqa.cli.main import main

KICK = "bvh/bandai/dataset-1_kick_normal_001.bvh"


@pytest.mark.render
def test_render_command_writes_a_still_and_a_sheet(corpus_dir: Path, tmp_path: Path) -> None:
    import imageio.v3 as iio

    still = tmp_path / "still.png"
    code = main(
        ["render", str(corpus_dir / KICK), "--frame", "60", "--compare", "--no-analyze",
         "--width", "200", "--height", "160", "-o", str(still)]
    )  # fmt: skip
    assert code == 0
    assert iio.imread(still).shape == (160, 400, 3)
    clip = tmp_path / "clip.gif"
    code = main(
        ["render", str(corpus_dir / KICK), "--interval", "UpperArm_R:10-14", "--no-analyze",
         "-o", str(clip)]
    )  # fmt: skip
    assert code == 0
    assert iio.imread(clip, index=None).shape[0] == 5


def test_render_command_rejects_a_bad_interval(corpus_dir: Path, tmp_path: Path) -> None:
    code = main(
        ["render", str(corpus_dir / KICK), "--interval", "UpperArm_R:20-10", "--no-analyze",
         "-o", str(tmp_path / "x.gif")]
    )  # fmt: skip
    assert code == 3
