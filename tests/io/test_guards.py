"""The read limits (``io/guards.py``): exact at their boundaries, and a deep rig read,
analysed and written without recursion when the limits allow it."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np
import pytest
from tests.api.test_hostile import bvh_text

from mocapqa.errors import TooLargeError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import format_bvh
from mocapqa.io.formats import read_take
from mocapqa.io.guards import ReadLimits, check_json_depth, check_line_length, check_take_input
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.options import AnalysisOptions


@pytest.mark.parametrize("chunk_edge", [0, 1, (1 << 20) - 3])
def test_line_length_is_exact_across_chunks(tmp_path: Path, chunk_edge: int) -> None:
    path = tmp_path / "lines.csv"
    longest = 2_000_000
    path.write_bytes(b"a" * chunk_edge + b"\n" + b"b" * longest + b"\nshort\n")
    check_line_length(path, longest)
    with pytest.raises(TooLargeError, match=r"line 2: .*max_line_bytes"):
        check_line_length(path, longest - 1)


def test_json_depth_is_exact(tmp_path: Path) -> None:
    path = tmp_path / "deep.json"
    path.write_bytes(b'{"a": [[[1]]], "b": "a [ in a string counts: the estimate refuses"}')
    check_json_depth(path, 4)
    with pytest.raises(TooLargeError, match="max_json_depth"):
        check_json_depth(path, 3)


def test_npz_limits_come_from_the_headers(tmp_path: Path) -> None:
    path = tmp_path / "big.npz"
    buffer = io.BytesIO()
    np.savez_compressed(buffer, positions=np.zeros((1000, 10, 3)), fps=np.float64(30))
    path.write_bytes(buffer.getvalue())
    check_take_input(path, "npz", ReadLimits(max_frame_points=10_000))
    with pytest.raises(TooLargeError, match=r"max_frame_points.* 1000 × 10"):
        check_take_input(path, "npz", ReadLimits(max_frame_points=9_999))
    with pytest.raises(TooLargeError, match="max_unpacked_bytes"):
        check_take_input(path, "npz", ReadLimits(max_unpacked_bytes=200_000))
    assert zipfile.is_zipfile(path)


def test_joint_count_counts_keywords_not_names(tmp_path: Path) -> None:
    path = tmp_path / "names.bvh"
    path.write_text(bvh_text(3, chain=True).replace("j1", "JOINT_ROOT"))
    check_take_input(path, "bvh", ReadLimits(max_joints=3))
    with pytest.raises(TooLargeError, match=r"max_joints.* got 3"):
        check_take_input(path, "bvh", ReadLimits(max_joints=2))


def test_a_999_joint_chain_is_read_analysed_and_written(tmp_path: Path) -> None:
    """Refused by the default limit at upload; read and processed fine when allowed."""
    path = tmp_path / "chain.bvh"
    path.write_text(bvh_text(999, chain=True))
    with pytest.raises(TooLargeError, match="max_joints"):
        read_take(path, limits=ReadLimits())
    motion = read_take(path, limits=ReadLimits(max_joints=1000))
    result = analyze(motion, AnalysisOptions(checks=("twist", "limits")))
    assert result.corrected_motion is not None
    text = format_bvh(result.corrected_motion)
    again = read_bvh(_write(tmp_path / "again.bvh", text))
    assert again.skeleton.n_joints == 999
    assert list(again.skeleton.parents) == [-1, *range(998)]


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path
