"""Errors at a take's ends in packed takes: the natural-side reference of a one-sided interval
never reaches across the neighbouring event, and a head's release that pairs as well with a
later onset is freed when the other reading leaves an interior event unexplained (real takes,
fit-take injections rebuilt as offsets)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tests.twist.chain_shifts import chain_of, with_shifts

from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh
from mocapqa.metrics.twist import rotation_errors_deg
from mocapqa.twist.analysis import analyze_twist


def _error_left(motion: Motion, shifted: Motion, refined: Motion, joint: int, rows: slice) -> float:
    """Share of the summed rotation error on ``rows`` that the refinement leaves."""
    before = rotation_errors_deg(motion.quats[rows, joint], shifted.quats[rows, joint])
    after = rotation_errors_deg(motion.quats[rows, joint], refined.quats[rows, joint])
    return float(after.sum() / before.sum())


@pytest.mark.parametrize(
    ("path", "segment", "side", "shifts"),
    [
        # The level shift 25–36 releases at 37, the frame before the tail's onset at 38: read
        # over the three frames before the anchor (37), the reference held two frames of that
        # shift (−46°) and the tail's level read 82° against its jump of 51°.
        (
            "bvh/bandai/dataset-2_raise-up-both-hands_normal_001.bvh", "lower_leg", "right",
            [(2, 5, -171.5), (8, 12, 26.1), (15, 23, 9.6), (25, 36, -46.1), (38, 50, 51.1)],
        ),
        # The shift 37–41 (112°) releases at 42, two frames before the tail's onset at 44.
        (
            "bvh/bandai/dataset-2_raise-up-right-hand_youthful_001.bvh", "forearm", "left",
            [(3, 12, -15.7), (14, 15, -96.8), (18, 35, -136.3), (37, 41, 112.2),
             (44, 53, 39.4)],
        ),
    ],
)  # fmt: skip
def test_a_tails_reference_stops_at_the_neighbouring_release(
    corpus_dir: Path, path: str, segment: str, side: str, shifts: list[tuple[int, int, float]]
) -> None:
    motion = read_bvh(corpus_dir / path)
    geometry = chain_of(motion, segment, side)
    shifted, offsets = with_shifts(motion, geometry, shifts)
    analysis = analyze_twist(shifted)
    first, last, _ = shifts[-1]
    tails = [f for f in analysis.found if f.side == "tail"]
    assert [(f.start_frame, f.end_frame) for f in tails] == [(first, last)]
    joint = geometry.chain.parent
    assert _error_left(motion, shifted, analysis.refined, joint, slice(first, last + 1)) <= 0.2
    # No clean frame of the chain moves.
    clean = offsets == 0.0
    moved = rotation_errors_deg(motion.quats[clean, joint], analysis.refined.quats[clean, joint])
    assert float(moved.max(initial=0.0)) < 1e-6


def test_a_heads_release_that_pairs_as_well_with_a_later_onset_is_freed(
    corpus_dir: Path,
) -> None:
    # A fit-take injection: the head's release at 8 (−164.3°) and the next shift's onset at 96
    # (+166.1°) cancel within the jump threshold, as do that onset and its own release at 104
    # (−166.6°). Both readings fit the jumps as well; the first leaves the release at 104, in
    # the middle of the take, unexplained, and read 8–95 (the clean frames) as the error.
    motion = read_bvh(corpus_dir / "bvh/cmu/iclone/002_09.bvh")
    geometry = chain_of(motion, "upper_leg", "left")
    shifts = [(0, 7, 164.5), (96, 103, 166.5), (204, 215, -109.4), (304, 319, -63.5),
              (397, 407, 67.0)]  # fmt: skip
    shifted, offsets = with_shifts(motion, geometry, shifts)
    analysis = analyze_twist(shifted)
    spans = [(f.side, f.start_frame, f.end_frame) for f in analysis.found]
    assert ("head", 0, 7) in spans
    assert ("", 96, 103) in spans
    joint = geometry.chain.parent
    assert _error_left(motion, shifted, analysis.refined, joint, slice(0, 8)) <= 0.2
    covered = np.zeros(motion.n_frames, dtype=bool)
    for f in analysis.found:
        covered[f.start_frame : f.end_frame + 1] = True
    assert not np.any(covered & (offsets == 0.0))
