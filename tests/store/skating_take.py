"""A BVH take with a foot skate made for the tests: a real standing take whose root drifts while
both feet stay planted (a slide as the feet benchmark injects it, written as a BVH file)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import write_bvh

STANDING_BVH = "bvh/bandai/dataset-2_raise-up-both-hands_normal_001.bvh"
"""A clean Bandai take standing on both feet (the feet check finds no skate), 51 frames, cm."""


def drifted_bvh(corpus_dir: Path, folder: Path, drift: float = 6.0) -> Path:
    """The standing Bandai take with a slide injected: the root drifts ``drift`` take units
    (cm; about 7 % of the leg length) along x, linearly over the take, while both feet stay
    planted, so each foot skates (sized in % of the body height, as a BVH stores no unit)."""
    motion = read_bvh(corpus_dir / STANDING_BVH)
    translations = motion.translations.copy()
    ramp = np.linspace(0.0, 1.0, motion.n_frames)
    translations[:, 0, 0] += drift * ramp
    path = folder / "standing_drifted.bvh"
    write_bvh(path, replace(motion, translations=translations))
    return path
