"""Rebuilding a corrected take from the raw one and the levels of chosen intervals.

A run lists every twist interval with its ``levels`` (``[start_frame, end_frame, offset_deg]``
per stretch of constant offset). Removing exactly the levels of the intervals a reviewer
accepted gives the take with those corrections and no others.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.errors import InputError
from mocapqa.twist.analysis import refined_hint
from mocapqa.twist.angles import chain_geometry
from mocapqa.twist.refine import refine_quats

__all__ = ["remove_levels"]

Level = tuple[int, int, float]
"""``(start_frame, end_frame, offset_deg)``: frames inclusive, 0-based."""


def remove_levels(
    motion: Motion,
    levels: Mapping[str, Sequence[Level]],
    mapping: dict[str, str] | None = None,
) -> Motion:
    """The take with these twist levels removed (and nothing else changed).

    Parameters
    ----------
    motion : Motion
        The raw take (not modified).
    levels : mapping of str to sequence of (int, int, float)
        Parent joint name of a limb chain → the levels to remove on it, degrees.
    mapping : dict, optional
        Role key → joint name overrides, as given to the analysis that found the levels.

    Returns
    -------
    Motion
        ``refine_quats(motion.quats, chains, offsets)`` with the levels as offsets; the
        motion itself when no level is given.

    Raises
    ------
    InputError
        For a joint that is not a limb chain's parent or a level outside the take's frames.
    """
    skeleton = motion.skeleton
    geometries = tuple(
        chain_geometry(skeleton, c) for c in limb_chains(find_roles(skeleton, mapping))
    )
    column = {skeleton.names[g.chain.parent]: c for c, g in enumerate(geometries)}
    offsets = np.zeros((motion.n_frames, len(geometries)))
    for joint, stretches in levels.items():
        if joint not in column:
            raise InputError(
                f"Expected a limb chain's parent joint, got {joint!r} (chains: {sorted(column)})"
            )
        for start, end, offset_deg in stretches:
            if not 0 <= start <= end < motion.n_frames:
                raise InputError(
                    f"Expected a level within frames 0–{motion.n_frames - 1}, got {start}–{end}"
                )
            offsets[start : end + 1, column[joint]] = np.deg2rad(offset_deg)
    if not offsets.any():
        return motion
    refined = refine_quats(motion.quats, geometries, offsets)
    changed = np.any(refined != motion.quats, axis=-1)
    return replace(motion, quats=refined, euler_hint_deg=refined_hint(motion, refined, changed))
