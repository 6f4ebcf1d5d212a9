"""Contact sheets, clips and the render service on a real take with a known, injected error."""

from __future__ import annotations

import sys
import threading
from pathlib import Path
from typing import Any

import imageio.v3 as iio
import numpy as np
import pytest
from pixels import BROKEN_FRAMES, BROKEN_JOINT, content_mask, red_mask

from mocapqa.core.motion import Motion
from mocapqa.errors import RenderUnavailableError, ShapeError
from mocapqa.render.clip import encode_clip, render_clip_frames
from mocapqa.render.scene import track_from_motion
from mocapqa.render.service import RenderService
from mocapqa.render.sheet import (
    frame_of_largest_difference,
    render_contact_sheet,
    tiles_from_intervals,
)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_frame_of_largest_difference_lies_in_the_broken_interval(
    kick: Motion, kick_broken: Motion
) -> None:
    raw, corrected = track_from_motion(kick_broken), track_from_motion(kick)
    frame = frame_of_largest_difference(raw.positions, corrected.positions, 30, 90)
    assert BROKEN_FRAMES[0] <= frame <= BROKEN_FRAMES[1]
    assert frame_of_largest_difference(raw.positions, None, 30, 90) == 60


def test_tiles_skip_unknown_joints_and_label_offsets(kick: Motion) -> None:
    track = track_from_motion(kick)
    tiles = tiles_from_intervals(
        [
            {"joint": BROKEN_JOINT, "start_frame": 40, "end_frame": 70, "offset_deg": -35.5},
            {"joint": "NoSuchJoint", "start_frame": 1, "end_frame": 2},
            {"joint": "Hips", "start_frame": 5, "end_frame": 5, "violation_deg": 12.0},
        ],
        track,
    )
    assert [t.label for t in tiles] == [
        f"{BROKEN_JOINT} · frames 40–70 · offset -35.5°",
        "Hips · frame 5 · violation 12.0°",
    ]


@pytest.mark.render
def test_contact_sheet_tiles_show_the_fix(kick: Motion, kick_broken: Motion, canvases: Any) -> None:
    raw, corrected = track_from_motion(kick_broken), track_from_motion(kick)
    tiles = tiles_from_intervals(
        [
            {"joint": BROKEN_JOINT, "start_frame": 40, "end_frame": 70, "offset_deg": 40.0},
            {"joint": "UpperLeg_L", "start_frame": 100, "end_frame": 110, "violation_deg": 9.0},
        ],
        raw,
        corrected,
    )
    size = 200
    sheet = render_contact_sheet(
        raw, tiles, corrected, columns=1, tile_width_px=size, tile_height_px=size, canvases=canvases
    )
    gap = 8
    assert sheet.shape == (2 * size + 3 * gap, 2 * size + 2 * gap, 3)
    first = sheet[gap : gap + size, gap : gap + 2 * size]
    second = sheet[2 * gap + size : 2 * gap + 2 * size, gap : gap + 2 * size]
    for tile in (first, second):
        assert content_mask(tile[:, :size]).mean() > 0.002
        assert red_mask(tile[:, :size]).any()
    # Below the captions: the broken arm moves between raw and corrected, the leg does not.
    moved = content_mask(first[45:, :size]) ^ content_mask(first[45:, size:])
    still = content_mask(second[45:, :size]) ^ content_mask(second[45:, size:])
    assert moved.sum() > 50
    assert still.sum() < 0.2 * moved.sum()


@pytest.mark.render
def test_gif_clip_has_every_frame_side_by_side(
    kick: Motion, kick_broken: Motion, canvases: Any
) -> None:
    raw, corrected = track_from_motion(kick_broken), track_from_motion(kick)
    frames = render_clip_frames(
        raw, 40, 69, corrected, width_px=150, height_px=150, canvases=canvases
    )
    assert len(frames) == 30
    assert frames[0].shape == (160, 320, 3)  # rounded up to multiples of 16, two views
    data = encode_clip(frames, "gif", raw.fps)
    decoded = iio.imread(data, extension=".gif", index=None)
    assert decoded.shape[0] == 30
    assert not np.array_equal(decoded[0], decoded[-1])  # the kick moves


@pytest.mark.render
def test_mp4_clip_has_sizes_divisible_by_16(kick: Motion, canvases: Any, tmp_path: Path) -> None:
    track = track_from_motion(kick)
    frames = render_clip_frames(track, 0, 9, width_px=100, height_px=90, canvases=canvases)
    data = encode_clip(frames, "mp4", track.fps)
    assert data[4:8] == b"ftyp"
    import imageio.v2 as imageio

    path = tmp_path / "clip.mp4"
    path.write_bytes(data)
    reader = imageio.get_reader(path, format="ffmpeg")
    try:
        first = reader.get_data(0)
    finally:
        reader.close()
    assert first.shape[0] % 16 == 0
    assert first.shape[1] % 16 == 0


def test_unknown_clip_format_is_rejected() -> None:
    with pytest.raises(ShapeError, match="Expected a clip format in"):
        encode_clip([np.zeros((16, 16, 3), dtype=np.uint8)], "avi", 30.0)


@pytest.mark.render
def test_service_serialises_renders_from_many_threads(kick: Motion) -> None:
    track = track_from_motion(kick)
    results: list[bytes] = []
    errors: list[BaseException] = []

    def request(frame: int) -> None:
        try:
            results.append(service.thumbnail(track, frame))
        except BaseException as e:  # pragma: no cover - reported below
            errors.append(e)

    with RenderService() as service:
        threads = [threading.Thread(target=request, args=(f,)) for f in (0, 50, 100, 150)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        still = service.still(track, 10)
        pair = service.side_by_side(track, track, 10)
    assert not errors
    assert len(results) == 4
    for png in [*results, still, pair]:
        assert png.startswith(PNG_SIGNATURE)
    assert iio.imread(pair).shape[1] == 2 * iio.imread(still).shape[1]


def test_missing_pyvista_raises_render_unavailable(monkeypatch: pytest.MonkeyPatch) -> None:
    from mocapqa.render.engine import load_pyvista

    monkeypatch.setitem(sys.modules, "pyvista", None)
    with pytest.raises(RenderUnavailableError, match="Expected pyvista with VTK to import"):
        load_pyvista()


NOT_APPLIED = [
    {"kind": "twist", "joint": BROKEN_JOINT, "start_frame": 40, "end_frame": 70,
     "offset_deg": 40.0, "confidence": 0.93, "applied": True},
    {"kind": "twist", "joint": BROKEN_JOINT, "start_frame": 100, "end_frame": 104,
     "offset_deg": -17.6, "confidence": 0.14, "applied": False},
    {"kind": "spin", "joint": "UpperLeg_L", "start_frame": 10, "end_frame": 12,
     "offset_deg": 180.0},
]  # fmt: skip


def test_tiles_of_intervals_not_applied_say_so(kick: Motion, kick_broken: Motion) -> None:
    # With apply=confident, a low-confidence interval is found but not applied: its tile
    # showed a 'corrected' panel all the same.
    raw, corrected = track_from_motion(kick_broken), track_from_motion(kick)
    applied, skipped, spin = tiles_from_intervals(NOT_APPLIED, raw, corrected)
    assert applied.not_applied is None
    assert skipped.not_applied == "not applied (confidence 0.14)"
    assert spin.not_applied == "not corrected (limb spin)"
    # The frame of a tile not applied is not chosen by the corrected take's differences.
    assert skipped.frame == 102


@pytest.mark.render
def test_contact_sheet_shows_no_corrected_pose_for_an_interval_not_applied(
    kick: Motion, kick_broken: Motion, canvases: Any
) -> None:
    raw, corrected = track_from_motion(kick_broken), track_from_motion(kick)
    tiles = tiles_from_intervals(NOT_APPLIED[:2], raw, corrected)
    size, gap = 200, 8
    sheet = render_contact_sheet(
        raw, tiles, corrected, columns=1, tile_width_px=size, tile_height_px=size, canvases=canvases
    )
    first = sheet[gap : gap + size, gap : gap + 2 * size]
    second = sheet[2 * gap + size : 2 * gap + 2 * size, gap : gap + 2 * size]
    green = (first[..., 1].astype(int) - first[..., 0] > 60) & (first[..., 1] > 120)
    assert green[45:, size:].any()
    # The interval not applied: the raw pose only, its right panel holds no pose, only the
    # caption at the top.
    assert red_mask(second[:, :size]).any()
    assert content_mask(second[45:, :size]).mean() > 0.002
    assert content_mask(second[45:, size:]).sum() == 0
    assert content_mask(second[:45, size:]).any()
