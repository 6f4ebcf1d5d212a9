"""Every BVH of the corpus reads, and write → read reproduces it.

The reference is the original file's text, tokenised here independently of the reader: a
hierarchy walk over whitespace tokens and ``float`` on every frame value.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from mocapqa.core.motion import Motion
from mocapqa.io.bvh import parse_bvh, read_bvh
from mocapqa.io.bvh_write import channel_values, format_bvh

PRECISION = 6


@dataclass
class ReferenceBvh:
    """What a BVH text says, read by the simplest possible tokeniser."""

    names: list[str] = field(default_factory=list)
    offsets: list[tuple[float, float, float]] = field(default_factory=list)
    channels: list[tuple[str, ...]] = field(default_factory=list)
    end_sites: list[tuple[str, tuple[float, float, float]]] = field(default_factory=list)
    n_frames: int = 0
    frame_time: float = 0.0
    values: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))


def tokenize_bvh(text: str) -> ReferenceBvh:
    """Read a well-formed BVH text without the package's code."""
    head, motion = text.split("MOTION", 1)
    tokens = head.split()
    ref = ReferenceBvh()
    stack: list[str] = []
    i = 0
    last_kind = ""
    while i < len(tokens):
        token = tokens[i]
        if token in ("ROOT", "JOINT"):
            ref.names.append(tokens[i + 1])
            ref.channels.append(())
            ref.offsets.append((0.0, 0.0, 0.0))
            last_kind = "joint"
            i += 2
        elif token == "End":
            last_kind = "end"
            i += 2
        elif token == "{":
            stack.append(last_kind if last_kind else "?")
            if last_kind == "joint":
                stack[-1] = ref.names[-1]
            last_kind = ""
            i += 1
        elif token == "}":
            stack.pop()
            i += 1
        elif token == "OFFSET":
            offset = (float(tokens[i + 1]), float(tokens[i + 2]), float(tokens[i + 3]))
            if stack[-1] == "end":
                owner = next(s for s in reversed(stack[:-1]) if s != "end")
                ref.end_sites.append((owner, offset))
            else:
                ref.offsets[-1] = offset
            i += 4
        elif token == "CHANNELS":
            count = int(tokens[i + 1])
            ref.channels[-1] = tuple(tokens[i + 2 : i + 2 + count])
            i += 2 + count
        else:
            i += 1
    lines = [line for line in motion.splitlines() if line.strip()]
    ref.n_frames = int(lines[0].split(":")[1])
    ref.frame_time = float(lines[1].split(":")[1])
    # numpy's own string-to-float conversion: neither of the reader's number paths.
    ref.values = np.array(" ".join(lines[2:]).split(), dtype=np.float64).reshape(ref.n_frames, -1)
    return ref


def assert_matches_reference(motion: Motion, ref: ReferenceBvh, values_tol: float) -> None:
    sk = motion.skeleton
    assert list(sk.names) == ref.names
    np.testing.assert_array_equal(sk.offsets, np.array(ref.offsets).reshape(-1, 3))
    assert [tuple(c) for c in sk.channels] == ref.channels
    assert [(sk.names[e.parent], e.offset) for e in sk.end_sites] == ref.end_sites
    assert motion.n_frames == ref.n_frames
    values = channel_values(motion)
    assert values.shape == ref.values.shape
    bound = values_tol + 4 * np.finfo(float).eps * np.abs(ref.values)
    worst = np.max(np.abs(values - ref.values) - bound, initial=-1.0)
    assert worst <= 0.0, f"channel values differ by up to {worst:.3g} beyond the bound"


def test_corpus_has_the_documented_bvh_files(bvh_files: list[Path], corpus_dir: Path) -> None:
    # The corpus' MANIFEST.tsv lists every file with its sha256; the BVH files found on disk
    # are exactly the ones it lists (the corpus grows: 005_05 joined the iClone folder).
    rows = (corpus_dir / "MANIFEST.tsv").read_text(encoding="utf-8").splitlines()
    listed = {row.split("\t")[0] for row in rows[1:] if row.split("\t")[0].endswith(".bvh")}
    found = {path.relative_to(corpus_dir).as_posix() for path in bvh_files}
    assert found == listed
    assert len(found) >= 61


def test_every_corpus_bvh_reads_and_round_trips(bvh_files: list[Path], tmp_path: Path) -> None:
    for path in bvh_files:
        text = path.read_bytes().decode("utf-8-sig")
        ref = tokenize_bvh(text)
        motion = read_bvh(path)
        # Read: the numbers as printed, exactly (the hint keeps the angles read).
        assert motion.fps == pytest.approx(1.0 / ref.frame_time, rel=1e-12)
        assert_matches_reference(motion, ref, values_tol=0.0)
        # Write → read: names, offsets, layouts and End Sites exactly; values to 6 decimals.
        written = tmp_path / path.name
        written.write_text(format_bvh(motion, PRECISION), encoding="utf-8")
        again = read_bvh(written)
        assert again.skeleton.root_translation == motion.skeleton.root_translation
        assert_matches_reference(again, ref, values_tol=0.5 * 10.0**-PRECISION)


@pytest.mark.parametrize(
    "relative",
    ["cmu/cmu_12_01_walk.bvh", "bandai/dataset-2_walk_elderly_001.bvh", "misc/bvh_test3.bvh"],
)
def test_number_readers_agree_exactly(corpus_dir: Path, relative: str) -> None:
    data = (corpus_dir / "bvh" / relative).read_bytes()
    by_arrow = parse_bvh(data, relative, number_reader="arrow")
    by_python = parse_bvh(data, relative, number_reader="python")
    np.testing.assert_array_equal(channel_values(by_arrow), channel_values(by_python))
    np.testing.assert_array_equal(by_arrow.quats, by_python.quats)


def test_reads_in_many_threads_at_once_agree(cmu_walk: Path) -> None:
    # A server reads takes concurrently: nothing in the reader may be shared between reads.
    alone = read_bvh(cmu_walk)
    with ThreadPoolExecutor(max_workers=6) as pool:
        motions = list(pool.map(read_bvh, [cmu_walk] * 18))
    for motion in motions:
        np.testing.assert_array_equal(motion.quats, alone.quats)
        np.testing.assert_array_equal(motion.translations, alone.translations)


def test_cmu_walk_matches_its_readme(cmu_walk: Path) -> None:
    motion = read_bvh(cmu_walk)
    # shared/data/README.md: 524 frames, Frame Time .0083333, 31 joints, 7 End Sites, ZYX.
    assert motion.n_frames == 524
    assert motion.fps == pytest.approx(1 / 0.0083333)
    assert motion.skeleton.n_joints == 31
    assert len(motion.skeleton.end_sites) == 7
    assert {motion.skeleton.rotation_order(j) for j in range(31)} == {"ZYX"}
    # Frame 0 is the synthetic T-pose: integer angles, e.g. -21 and 21 degrees.
    angles = channel_values(motion)[0, 3:]
    np.testing.assert_array_equal(angles, np.round(angles))
    assert {-21.0, 21.0} <= set(angles.tolist())


def test_changed_rotations_are_written_from_the_quaternions(cmu_walk: Path) -> None:
    from dataclasses import replace

    from scipy.spatial.transform import Rotation

    from mocapqa.kinematics.euler import quats_from_euler

    motion = read_bvh(cmu_walk)
    joint = motion.skeleton.index("LeftForeArm")
    quats = motion.quats.copy()
    twist = Rotation.from_euler("Y", 10, degrees=True)
    quats[:, joint] = (Rotation.from_quat(quats[:, joint]) * twist).as_quat()
    changed = replace(motion, quats=quats)  # keeps the hint read from the file
    values = channel_values(changed)
    column = sum(len(c) for c in motion.skeleton.channels[:joint])
    angles = np.deg2rad(values[:, column : column + 3])
    written = quats_from_euler(angles, "ZYX")
    gap = np.minimum(
        np.abs(written - quats[:, joint]).max(axis=-1),
        np.abs(written + quats[:, joint]).max(axis=-1),
    )
    assert gap.max() < 1e-9
    # Untouched joints keep the file's numbers exactly.
    np.testing.assert_array_equal(values[:, :column], channel_values(motion)[:, :column])
    # The new angles stay near the file's (no 360° or second-solution jumps).
    original = channel_values(motion)[:, column : column + 3]
    assert np.max(np.abs(values[:, column : column + 3] - original)) < 30.0
