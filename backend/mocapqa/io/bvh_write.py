"""BVH writer: the hierarchy as read, channel values in each joint's own order.

Conventions
-----------
* Offsets are written with the shortest repr that reads back to the same float, so a
  read → write → read round trip keeps names, offsets, channel layouts and End Sites exactly.
* Rotations are written as continuous Euler angles in each joint's channel order (see
  :func:`mocapqa.kinematics.euler.euler_from_quats`). Where the motion still holds the angles it
  was read with (``euler_hint_deg``) and they describe the same rotation, those numbers are
  written verbatim; elsewhere the equivalent triple nearest to them is chosen, so nothing
  jumps by 360° or flips to the second Euler solution.
* Files are written to a temporary name and renamed into place (:mod:`mocapqa.io.atomic`).
"""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import numpy.typing as npt

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import POSITION_CHANNELS, Motion
from mocapqa.io.atomic import write_text
from mocapqa.kinematics.euler import euler_from_quats, quats_from_euler

__all__ = ["channel_values", "format_bvh", "frame_lines", "write_bvh"]

_SAME_ROTATION = 1e-12  # quaternion component gap under which the Euler hint is written


def _format_number(value: float) -> str:
    text = repr(float(value))
    if text.endswith(".0"):
        text = text[:-2]
    return "0" if text == "-0" else text


def format_bvh(motion: Motion, precision: int = 6) -> str:
    """BVH text for a motion: hierarchy as read, continuous Euler angles in each joint's order.

    Parameters
    ----------
    motion : Motion
        The take to write.
    precision : int, default 6
        Decimal places of channel values.

    Returns
    -------
    str
        The file's text, LF line endings.
    """
    sk = motion.skeleton
    out: list[str] = ["HIERARCHY"]
    children: dict[int, list[int]] = {}
    for j, p in enumerate(sk.parents):
        children.setdefault(int(p), []).append(j)

    sites: dict[int, list[str]] = {}
    for site in sk.end_sites:
        sites.setdefault(int(site.parent), []).append(
            " ".join(_format_number(v) for v in site.offset)
        )
    # Depth-first with an explicit stack (no recursion, so a chain of any length is written):
    # an int opens a joint, a negative one -(j + 1) closes it after its children.
    stack = [item for r in reversed(children.get(-1, [])) for item in (-(r + 1), r)]
    depth = 0
    while stack:
        j = stack.pop()
        if j >= 0:
            pad = "\t" * depth
            keyword = "ROOT" if sk.parents[j] < 0 else "JOINT"
            out.append(f"{pad}{keyword} {sk.names[j]}")
            out.append(f"{pad}{{")
            off = " ".join(_format_number(v) for v in sk.offsets[j])
            out.append(f"{pad}\tOFFSET {off}")
            if sk.channels[j]:
                out.append(f"{pad}\tCHANNELS {len(sk.channels[j])} {' '.join(sk.channels[j])}")
            for c in reversed(children.get(j, [])):
                stack.extend((-(c + 1), c))
            depth += 1
        else:
            depth -= 1
            pad = "\t" * depth
            for site_off in sites.get(-j - 1, []):
                out.append(f"{pad}\tEnd Site")
                out.append(f"{pad}\t{{")
                out.append(f"{pad}\t\tOFFSET {site_off}")
                out.append(f"{pad}\t}}")
            out.append(f"{pad}}}")

    out.append("MOTION")
    out.append(f"Frames: {motion.n_frames}")
    out.append(f"Frame Time: {1.0 / motion.fps:.7g}")
    values = channel_values(motion)
    if values.size:
        out.extend(frame_lines(values, precision))
    return "\n".join(out) + "\n"


def frame_lines(values: FloatArray, precision: int = 6) -> list[str]:
    """One line per frame: the values ``(F, C)`` in fixed point, ``precision`` decimals, one
    space apart ("%.6f" of each value rounded first, so -0.0 and tiny negatives read "0.000000").

    Formatting was a third of a batch take's time (writing ``corrected.bvh``, docs/batch.md):
    with pyarrow, each value's digits are the integer ``rint(value · 10**precision)``, written
    by Arrow's decimal-to-string cast and joined column by column (about 2.5× faster); the text
    is the same as Python's ``%`` formatting, which remains for values out of that range,
    non-finite values, or a missing pyarrow.

    Parameters
    ----------
    values : ndarray, shape (F, C)
        Channel values.
    precision : int, default 6
        Decimal places.
    """
    scaled = np.rint(values * 10.0**precision)
    if 0 <= precision <= 12 and np.all(np.abs(scaled) < 2.0**62):
        lines = _arrow_lines(scaled.astype(np.int64), precision)
        if lines is not None:
            return lines
    # Rounding first and adding 0.0 turns -0.0 (and tiny negatives) into "0.000000".
    rows = (np.round(values, precision) + 0.0).tolist()
    line = " ".join([f"%.{precision}f"] * values.shape[1])
    return [line % tuple(row) for row in rows]


def _arrow_lines(digits: npt.NDArray[np.int64], precision: int) -> list[str] | None:
    """Lines of fixed-point numbers whose digits (scaled by ``10**precision``) are given."""
    try:
        arrow = importlib.import_module("pyarrow")
        compute = importlib.import_module("pyarrow.compute")
    except ImportError:
        return None
    n_frames, n_channels = digits.shape
    by_column = np.ascontiguousarray(digits.T).ravel()
    # A 128-bit decimal holding these digits: low word the value, high word its sign.
    words = np.empty((by_column.size, 2), dtype=np.int64)
    words[:, 0] = by_column
    words[:, 1] = by_column >> 63
    decimals = arrow.Array.from_buffers(
        arrow.decimal128(38, precision), by_column.size, [None, arrow.py_buffer(words)]
    )
    text = compute.cast(decimals, arrow.string())
    columns = [text.slice(c * n_frames, n_frames) for c in range(n_channels)]
    return list(compute.binary_join_element_wise(*columns, " ").to_pylist())


def channel_values(motion: Motion) -> FloatArray:
    """Channel values ``(F, C)`` in file order: positions in file units, angles in degrees."""
    sk = motion.skeleton
    n_channels = sum(len(c) for c in sk.channels)
    values = np.zeros((motion.n_frames, n_channels))
    euler = np.zeros((motion.n_frames, sk.n_joints, 3))
    by_order: dict[str, list[int]] = {}
    for j in range(sk.n_joints):
        order = sk.rotation_order(j)
        if order:
            by_order.setdefault(order, []).append(j)
    for order, joints in by_order.items():
        quats = motion.quats[:, joints]
        if motion.euler_hint_deg is None:
            euler[:, joints] = np.rad2deg(euler_from_quats(quats, order))
            continue
        hint_deg = motion.euler_hint_deg[:, joints]
        # Where the hint still describes the rotation, write it verbatim: near gimbal lock the
        # quaternion → Euler step loses digits that the file had. Compared by components, not
        # by angle: arccos near 1 turns a 1e-16 difference in the dot product into 1e-8 rad.
        from_hint = quats_from_euler(hint_deg, order, degrees=True)
        gap = np.minimum(
            np.max(np.abs(from_hint - quats), axis=-1), np.max(np.abs(from_hint + quats), axis=-1)
        )
        changed = gap >= _SAME_ROTATION
        chosen = hint_deg.copy()
        if np.any(changed):
            # Elementwise with a reference, so only the changed rotations are converted.
            chosen[changed] = np.rad2deg(
                euler_from_quats(quats[changed], order, np.deg2rad(hint_deg[changed]))
            )
        euler[:, joints] = chosen
    column = 0
    for j, chans in enumerate(sk.channels):
        k_rot = 0
        for channel in chans:
            if channel in POSITION_CHANNELS:
                values[:, column] = motion.translations[:, j, "XYZ".index(channel[0])]
            else:
                values[:, column] = euler[:, j, k_rot]
                k_rot += 1
            column += 1
    return values


def write_bvh(path: str | Path, motion: Motion, precision: int = 6) -> None:
    """Write a motion as BVH, whole or not at all (:mod:`mocapqa.io.atomic`).

    Parameters
    ----------
    path : str or Path
        Destination file.
    motion : Motion
        The take.
    precision : int, default 6
        Decimal places of channel values.
    """
    write_text(path, format_bvh(motion, precision))
