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


@pytest.mark.parametrize(("width", "height"), [("8193", "16"), ("100000", "100000"), ("15", "480")])
def test_render_refuses_an_image_size_out_of_range_before_reading(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], width: str, height: str
) -> None:
    # 100,000 × 100,000 px aborted VTK (exit 134); 8,193 × 16 rendered.
    out = tmp_path / "r.png"
    code = main(
        ["render", str(corpus_dir / KICK), "--frame", "0", "--no-analyze",
         "--width", width, "--height", height, "-o", str(out)]
    )  # fmt: skip
    assert code == 3
    err = capsys.readouterr().err
    assert "--width/--height: Expected an image width and height of 16 to 8192 px" in err
    assert not out.exists()


def test_still_options_bound_the_image_size() -> None:
    from mocapqa.errors import ShapeError
    from mocapqa.render.still import MAX_SIDE_PX, MIN_SIDE_PX, StillOptions

    StillOptions(width_px=MAX_SIDE_PX, height_px=MIN_SIDE_PX)
    for size in ((MAX_SIDE_PX + 1, 480), (640, 100_000), (MIN_SIDE_PX - 1, 480)):
        with pytest.raises(ShapeError, match="16 to 8192 px"):
            StillOptions(width_px=size[0], height_px=size[1])


def test_contact_sheet_of_a_run_says_which_intervals_were_not_applied(corpus_dir: Path) -> None:
    from mocapqa.cli.report import analyze_take, sheet_tiles

    # 005_05's real knee twists, none applied (a run with twist_apply "none").
    run = analyze_take(corpus_dir / "bvh/cmu/iclone/005_05.bvh", {"twist_apply": "none"})
    twists = [f for f in run.analysis["findings"] if f["kind"] == "twist"]
    assert twists
    assert not any(f["applied"] for f in twists)
    tiles = sheet_tiles(run)
    shown = [t for t in tiles if "offset" in t.label]
    assert shown
    for tile, finding in zip(shown, twists, strict=False):
        assert tile.not_applied == f"not applied (confidence {finding['confidence']:.2f})"
