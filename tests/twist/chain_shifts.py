"""Twist offsets put on one chain of a real take, as the injection puts them (the child
compensated): the tests of errors at a take's ends build their cases with these."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.twist.angles import ChainGeometry, chain_geometry
from mocapqa.twist.refine import refine_quats


def chain_of(motion: Motion, segment: str, side: str) -> ChainGeometry:
    """The geometry of the take's ``side`` ``segment`` chain (``"lower_leg"``, ``"left"``)."""
    chains = limb_chains(find_roles(motion.skeleton))
    chain = next(c for c in chains if c.segment == segment and c.side == side)
    return chain_geometry(motion.skeleton, chain)


def with_shifts(
    motion: Motion, geometry: ChainGeometry, shifts: list[tuple[int, int, float]]
) -> tuple[Motion, np.ndarray]:
    """The take with twist offsets ``(first, last, degrees)`` on one chain (child compensated,
    as the injection does), and the offsets per frame (radians)."""
    offsets = np.zeros((motion.n_frames, 1))
    for first, last, degrees in shifts:
        offsets[first : last + 1] = np.deg2rad(degrees)
    return replace(motion, quats=refine_quats(motion.quats, (geometry,), -offsets)), offsets[:, 0]
