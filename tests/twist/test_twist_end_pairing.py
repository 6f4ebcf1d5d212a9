"""Errors at a take's ends next to other errors: a head's release that bracket matching paired
with a later interval's onset, an end event beside a neighbouring level shift's event, and a
burst beside the take's start that must not read as a head (real takes, injected offsets)."""

from __future__ import annotations

import shutil
import zlib
from pathlib import Path

import numpy as np
import pytest
from tests.twist.chain_shifts import chain_of, with_shifts

from mocapqa.cli.main import main
from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh
from mocapqa.metrics.twist import rotation_errors_deg
from mocapqa.twist.analysis import analyze_twist
from mocapqa.twist.inject import inject_twist_errors


def _corrected(motion: Motion, shifted: Motion, joint: int, rows: slice) -> bool:
    """Whether the default refinement leaves at most 20 % of the error on ``rows``."""
    refined = analyze_twist(shifted).refined
    before = rotation_errors_deg(motion.quats[rows, joint], shifted.quats[rows, joint])
    after = rotation_errors_deg(motion.quats[rows, joint], refined.quats[rows, joint])
    return bool(after.sum() <= 0.2 * before.sum())


def test_a_heads_release_paired_across_a_nested_interval_is_freed(corpus_dir: Path) -> None:
    # A fit-take injection: the head's release at 12 (+167.9°) cancelled the onset at 72
    # (−147.9°) across the pair 35–48, so every interval after it was read between one error's
    # release and the next one's onset (12–71, 76–100, 105–123, and a tail 133–151), and the
    # head was not found. Matched again without the first event, each onset pairs with its
    # own release.
    motion = read_bvh(corpus_dir / "bvh/bandai/dataset-1_guide_masculinity_001.bvh")
    geometry = chain_of(motion, "upper_arm", "right")
    shifts = [(0, 11, -167.9), (35, 47, -73.9), (72, 75, -147.9), (101, 104, -174.1),
              (124, 132, -164.8)]  # fmt: skip
    shifted, offsets = with_shifts(motion, geometry, shifts)
    analysis = analyze_twist(shifted, apply="all")
    spans = [(f.side, f.start_frame, f.end_frame) for f in analysis.found]
    assert ("head", 0, 11) in spans
    assert not [s for s in spans if s[0] == "tail"]
    # No reported interval reaches the clean frames between the errors.
    covered = np.zeros(motion.n_frames, dtype=bool)
    for f in analysis.found:
        covered[f.start_frame : f.end_frame + 1] = True
    assert not np.any(covered & (offsets == 0.0))
    assert _corrected(motion, shifted, geometry.chain.parent, slice(0, 12))


def test_a_tail_onset_beside_a_level_shifts_release_is_corrected(corpus_dir: Path) -> None:
    # A fit-take injection on a 54-frame Bandai take: the level shift 34–47 releases at 48,
    # two frames before the tail's onset at 50. That release is explained by its own onset,
    # so it is no burst of the tail's.
    motion = read_bvh(corpus_dir / "bvh/bandai/dataset-2_raise-up-right-hand_youthful_001.bvh")
    geometry = chain_of(motion, "forearm", "right")
    shifts = [(2, 16, 167.2), (18, 30, -79.1), (34, 47, 34.0), (50, 53, -138.9)]
    shifted, _ = with_shifts(motion, geometry, shifts)
    found = analyze_twist(shifted).found
    assert ("tail", 50, 53) in [(f.side, f.start_frame, f.end_frame) for f in found]
    assert _corrected(motion, shifted, geometry.chain.parent, slice(50, 54))


def test_a_burst_beside_the_takes_start_is_not_read_as_a_head(corpus_dir: Path) -> None:
    # The fit-take burst injection (seed 0, first repeat) whose first flip, at frame 21, pairs
    # with its second: matched again without it, the second flip would pair with the first
    # flip of a later burst (40–47) that returns by itself, and frames 0–20 would read as a
    # head of −87°. A burst whose flips return keeps its events.
    path = corpus_dir / "bvh/bandai/dataset-1_run_giant_001.bvh"
    motion = read_bvh(path)
    rng = np.random.default_rng((0, zlib.crc32(path.name.encode()), 0))
    corrupted, truth = inject_twist_errors(motion, rng, kind="burst")
    assert (21, 22) in [(i.start_frame, i.end_frame) for i in truth.intervals]
    analysis = analyze_twist(corrupted, apply="all")
    assert not [f for f in analysis.found if f.side == "head"]


def test_bench_twist_ends_only_prints_only_the_ends_table(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "bandai").mkdir()
    for name in ("dataset-2_walk_normal_001.bvh", "dataset-1_bow_sad_001.bvh"):
        shutil.copy(corpus_dir / "bvh" / "bandai" / name, tmp_path / "bandai" / name)
    assert main(["bench", "twist", "--data", str(tmp_path), "--repeats", "1", "--ends-only"]) == 0
    out = capsys.readouterr().out
    assert "Errors at the take's ends" in out
    assert "Table 1" not in out
    rows = [line.split("│")[1:4] for line in out.splitlines() if line.startswith("│")]
    chosen = {(end.strip(), apply.strip(), group.strip()) for end, apply, group in rows}
    for end in ("tail", "head"):
        for apply in ("confident", "all"):
            assert (end, apply, "all: fit set") in chosen
            assert (end, apply, "bandai: held-out") in chosen


@pytest.mark.parametrize(
    ("name", "seed", "repeat", "segment", "side"),
    [
        ("cmu/iclone/003_02.bvh", 4, 2, "upper_arm", "left"),
        ("bandai/dataset-1_bye_childish_001.bvh", 2, 3, "lower_leg", "right"),
    ],
)
def test_a_heads_release_is_freed_beside_a_burst_that_the_new_reading_keeps(
    corpus_dir: Path, name: str, seed: int, repeat: int, segment: str, side: str
) -> None:
    # Fit-take head injections. The head's release paired with a later onset in a group that
    # also held two events one burst gap apart that cancel (003_02: 115 and 121, the ends of a
    # 6-frame shift); the whole group was kept as a burst, so the re-pairing without the
    # first event was refused and the clean frames between two errors read as one (003_02:
    # 48–142 at 160°, applied). The re-pairing keeps those two events together, so it is taken.
    path = corpus_dir / "bvh" / name
    motion = read_bvh(path)
    rng = np.random.default_rng((seed, zlib.crc32(path.name.encode()), repeat))
    corrupted, truth = inject_twist_errors(motion, rng, ends="head")
    joint = chain_of(motion, segment, side).chain.parent
    clean = ~truth.error_mask[:, joint]
    refined = analyze_twist(corrupted).refined
    moved = rotation_errors_deg(motion.quats[clean, joint], refined.quats[clean, joint])
    assert float(moved.max()) < 5.0
    head = min((i for i in truth.intervals if i.joint == motion.skeleton.names[joint]),
               key=lambda i: i.start_frame)  # fmt: skip
    assert head.start_frame == 0
    assert _corrected(motion, corrupted, joint, slice(0, head.end_frame + 1))
