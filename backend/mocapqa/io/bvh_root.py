"""Why a BVH root position was read the way it was ("add" or "replace" of the root OFFSET).

The BVH convention, and Blender's importer, take the root's position channels as absolute
positions that *replace* its OFFSET. Character Creator exports keep a large rest OFFSET on the
root and write small deltas in the channels; read as absolute, such a body sits near the
origin, under the floor. :func:`mocapqa.io.bvh.parse_bvh` with ``root_translation="auto"``
detects this (along the OFFSET's largest axis, the median |channel| under a quarter of the
OFFSET means deltas) and *adds* the channels to the OFFSET. This module says which reading was
used and why, in words, for ``mocapqa info``, the API and reports.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from mocapqa.core.motion import Motion

__all__ = ["ROOT_TRANSLATIONS", "explain_root_translation"]

ROOT_TRANSLATIONS = ("auto", "add", "replace")
"""Choices of how to read the root position: detect, add to the OFFSET, replace it."""


def explain_root_translation(
    motion: Motion, requested: Literal["auto", "add", "replace"] = "auto"
) -> str:
    """One sentence: how the root position was read and why.

    Parameters
    ----------
    motion : Motion
        The take as read (its ``skeleton.root_translation`` is the reading used).
    requested : {"auto", "add", "replace"}
        What the reader was asked for: ``"auto"`` (detected) or a choice by the user.

    Returns
    -------
    str
        For example ``"add (detected): the root's Y channel has median |value| 2.1, under a
        quarter of its OFFSET 105, so the channels are deltas from the rest OFFSET ..."``.
    """
    skeleton = motion.skeleton
    mode = skeleton.root_translation
    root_offset = skeleton.offsets[0]
    has_position = any(c.endswith("position") for c in skeleton.channels[0])
    if not has_position:
        return f"{mode}: the root has no position channels, so it stays at its OFFSET"
    if not np.any(root_offset):
        return f"{mode}: the root OFFSET is zero, so adding and replacing give the same positions"
    axis = int(np.argmax(np.abs(root_offset)))
    offset = float(root_offset[axis])
    if motion.n_frames:
        median = float(np.median(np.abs(motion.translations[:, 0, axis])))
    else:
        median = float("nan")
    name = "XYZ"[axis]
    measured = (
        f"the root's {name} channel has median |value| {median:.4g} against its OFFSET {offset:.4g}"
    )
    if requested != "auto":
        return (
            f"{mode} (chosen by the user): {measured}. Blender's importer always replaces the "
            "OFFSET with the channels"
        )
    if mode == "add":
        return (
            f"add (detected): {measured}, under a quarter of it, so the channels are read as "
            "deltas from the rest OFFSET (Character Creator style). Blender's importer takes "
            "them as absolute positions, so there the body stands about "
            f"{abs(offset):.4g} units lower"
        )
    return (
        f"replace (detected): {measured}, so the channels are absolute positions that replace "
        "the OFFSET (the BVH convention, as Blender reads them)"
    )
