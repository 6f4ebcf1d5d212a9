"""Off-screen stills of real takes: not blank, upright, and raw | corrected differ where fixed."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from pixels import BROKEN_FRAMES, BROKEN_JOINT, bounding_box, content_mask, red_mask

from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh
from mocapqa.io.formats import read_take
from mocapqa.render.scene import SkeletonTrack, track_from_keypoints, track_from_motion
from mocapqa.render.still import StillOptions, render_side_by_side, render_still, render_thumbnail

pytestmark = pytest.mark.render

OPTIONS = StillOptions(width_px=320, height_px=320)
HEAD_WORDS = ("head", "nose")


def _head_flags(track: SkeletonTrack) -> np.ndarray:
    flags = np.array([any(w in n.lower() for w in HEAD_WORDS) for n in track.names])
    assert flags.any()
    return flags


def _track(corpus_dir: Path, relative: str) -> SkeletonTrack:
    take = read_take(corpus_dir / relative)
    if isinstance(take, Motion):
        return track_from_motion(take)
    assert isinstance(take, KeypointSequence)
    return track_from_keypoints(take)


@pytest.mark.parametrize(
    "relative",
    [
        "bvh/cmu/cmu_12_01_walk.bvh",  # Y up, travels far
        "bvh/misc/bvh_example.bvh",  # Z up
        "keypoints/mediapipe/etfrobotics_full-body-kinematics/landmarks.csv",  # y down
    ],
)
def test_still_shows_an_upright_skeleton(corpus_dir: Path, relative: str, canvases: Any) -> None:
    track = _track(corpus_dir, relative)
    frame = track.n_frames // 2
    image = render_still(
        track, frame, _head_flags(track), title="", options=OPTIONS, canvases=canvases, legend=False
    )
    assert image.shape == (320, 320, 3)
    assert image.dtype == np.uint8
    assert image.std() > 5  # not a flat colour
    body = content_mask(image)
    share = body.mean()
    assert 0.0005 < share < 0.5, f"skeleton covers {share:.3%} of the image"
    top, bottom, _left, _right = bounding_box(body)
    assert bottom - top > 0.15 * image.shape[0], "skeleton too small to read"
    assert top > 0 or bottom < image.shape[0] - 1, "skeleton should fit the frame"
    # The flagged head is drawn red and sits in the upper part of the skeleton: the up axis
    # is right for this rig.
    heads = red_mask(image)
    assert heads.any()
    head_row = float(np.flatnonzero(heads.any(axis=1)).mean())
    assert head_row < top + 0.35 * (bottom - top)


def test_side_by_side_differs_only_where_a_fix_was_made(
    kick: Motion, kick_broken: Motion, canvases: Any
) -> None:
    raw, corrected = track_from_motion(kick_broken), track_from_motion(kick)
    joint = kick.skeleton.index(BROKEN_JOINT)
    flags = np.zeros((kick.n_frames, kick.skeleton.n_joints), dtype=bool)
    flags[BROKEN_FRAMES[0] : BROKEN_FRAMES[1] + 1, joint] = True
    inside = render_side_by_side(
        raw, corrected, 55, flags, titles=("", ""), options=OPTIONS, canvases=canvases
    )
    outside = render_side_by_side(
        raw, corrected, 10, flags, titles=("", ""), options=OPTIONS, canvases=canvases
    )
    assert inside.shape == (320, 640, 3)
    # Between the caption row and the legend, compare the skeleton pixels of the two halves.
    left, right = inside[40:250, :320], inside[40:250, 320:]
    changed = content_mask(left) ^ content_mask(right)
    assert changed.sum() > 100, "the fixed arm should move between raw and corrected"
    # An unchanged frame draws the same twice, up to a few antialiased edge pixels.
    unchanged = content_mask(outside[40:250, :320]) ^ content_mask(outside[40:250, 320:])
    assert unchanged.sum() < 0.1 * changed.sum()
    # The moved pixels lie around the flagged arm, not elsewhere in the picture.
    arm = red_mask(left)
    top, bottom, left_col, right_col = bounding_box(arm)
    rows, cols = np.nonzero(changed)
    near = (np.abs(rows - (top + bottom) / 2) < 120) & (
        np.abs(cols - (left_col + right_col) / 2) < 120
    )
    assert near.mean() > 0.9


def test_thumbnail_is_small_and_not_blank(cmu_walk: Path, canvases: Any) -> None:
    image = render_thumbnail(track_from_motion(read_bvh(cmu_walk)), canvases=canvases)
    assert image.shape == (144, 192, 3)
    assert content_mask(image).any()


def test_still_rejects_a_frame_outside_the_take(cmu_walk: Path) -> None:
    from mocapqa.errors import ShapeError

    track = track_from_motion(read_bvh(cmu_walk))
    with pytest.raises(ShapeError, match="Expected a frame in"):
        render_still(track, track.n_frames)
