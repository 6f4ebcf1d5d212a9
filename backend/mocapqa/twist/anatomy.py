"""Anatomy evidence of a twist interval: is the raw roll outside the natural range, the fix inside?

The joint-limits model of the take's rig (:func:`mocapqa.limits.storage.load_default_model`: the
canonical model, or a shipped per-rig model where that is preferred, ``docs/limits.md``) gives,
for every role joint, the range of rotations seen on clean takes of every rig. A twist interval
on a chain rolls the parent segment about its bone and counter-rotates the child; so for each
interval this module reads, on the interval's frames only:

* ``raw_deg``: the largest twist of the parent joint beyond its natural range (degrees, the
  ``twist_deg`` distance of :func:`mocapqa.limits.occupancy.evaluate`), as read;
* ``fixed_deg``: the same once the interval's own levels are removed (the other intervals left
  as they are), exactly as :func:`mocapqa.twist.refine.refine_quats` would write it;
* ``outward_deg``: the most the correction moves the parent's twist of any frame of the
  interval toward the edge of its range (or further past it), degrees; a level removed from
  frames whose roll was natural moves them off the middle of the range even when it does not
  take them outside;
* ``child_raw_deg``, ``child_fixed_deg``: the child joint's whole distance outside its range
  (swing and twist), raw and corrected: the correction turns the child relative to the parent
  about the parent's bone, which for a foot or a hand is mostly a swing.

A joint the model does not check reads 0 both ways, and ``checked`` says whether the parent
was read. The work is a canonical charting of ``2 × Σ interval lengths`` frames (raw and
corrected rows of every interval), plus, for a rig the model holds no frames of, the at most
4,000 evenly spaced frames of the take its canonical frames are estimated from
(:func:`mocapqa.limits.canonical.pose_sample`), without the interval frames, as the limits
check does.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError, LimitsFileError
from mocapqa.twist.angles import ChainGeometry
from mocapqa.twist.refine import refine_quats

if TYPE_CHECKING:  # detect imports the confidence module, which reads this one
    from mocapqa.limits.model import LimitsModel
    from mocapqa.twist.detect import DetectedInterval

__all__ = ["AnatomyEvidence", "anatomy_evidence"]


@dataclass(frozen=True, slots=True)
class AnatomyEvidence:
    """Per interval, how far the parent's twist and the child's rotation sit outside their
    natural range before and after removing the interval alone.

    Parameters
    ----------
    raw_deg, fixed_deg : ndarray, shape (N,)
        Largest twist of the parent joint beyond its range over the interval's frames, raw and
        corrected, degrees (0 inside).
    outward_deg : ndarray, shape (N,)
        Largest move of the parent's twist toward or past the range's edge by the correction
        over the interval's frames, degrees (≤ 0 when every frame moves inwards).
    child_raw_deg, child_fixed_deg : ndarray, shape (N,)
        Largest distance of the child joint outside its range (swing and twist), raw and
        corrected, degrees.
    checked : ndarray of bool, shape (N,)
        Whether the limits model reads the interval's parent joint.
    """

    raw_deg: FloatArray
    fixed_deg: FloatArray
    outward_deg: FloatArray
    child_raw_deg: FloatArray
    child_fixed_deg: FloatArray
    checked: BoolArray

    @classmethod
    def empty(cls, n: int) -> AnatomyEvidence:
        """No anatomy read for ``n`` intervals (no model covers the rig)."""
        zeros = np.zeros(n)
        return cls(zeros, zeros, zeros, zeros, zeros, np.zeros(n, dtype=bool))


def _model_for(motion: Motion, mapping: Mapping[str, str] | None) -> LimitsModel | None:
    from mocapqa.limits.storage import load_default_model

    try:
        return load_default_model(motion.skeleton, mapping)
    except (LimitsFileError, InputError):
        return None


def anatomy_evidence(
    motion: Motion,
    geometries: Sequence[ChainGeometry],
    found: Sequence[DetectedInterval],
    detected: FloatArray,
    mapping: Mapping[str, str] | None = None,
    model: LimitsModel | None = None,
) -> AnatomyEvidence:
    """Anatomy evidence of every interval found on a take.

    Parameters
    ----------
    motion : Motion
        The take as read.
    geometries : sequence of ChainGeometry, length C
    found : sequence of DetectedInterval, length N
    detected : ndarray, shape (F, C)
        Offsets of every interval found, radians.
    mapping : mapping, optional
        Role key → joint name overrides (as for the limits check).
    model : LimitsModel, optional
        The limits model; the shipped default for the rig when omitted.

    Returns
    -------
    AnatomyEvidence
        All zeros and ``checked`` False when no model covers the rig.
    """
    # The limits stack (scipy among it) is imported when there is an interval to read, so a
    # module that only names the twist options does not pay for it.
    from mocapqa.limits.analysis import charted
    from mocapqa.limits.canonical import pose_sample, rig_key
    from mocapqa.limits.intervals import wrap
    from mocapqa.limits.occupancy import evaluate, twist_bounds

    n = len(found)
    if n == 0:
        return AnatomyEvidence.empty(0)
    model = _model_for(motion, mapping) if model is None else model
    if model is None:
        return AnatomyEvidence.empty(n)
    lengths = np.array([i.end_frame - i.start_frame + 1 for i in found], dtype=np.intp)
    starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    block = np.repeat(np.arange(n), lengths)
    first = np.array([i.start_frame for i in found], dtype=np.intp)
    rows = first[block] + np.arange(len(block)) - starts[block]
    chain_of = np.array([i.chain for i in found], dtype=np.intp)
    # Each interval's block of rows, with its own levels only, on its own chain.
    offsets = np.zeros((len(rows), len(geometries)))
    offsets[np.arange(len(rows)), chain_of[block]] = detected[rows, chain_of[block]]
    raw = motion.quats[rows]
    stacked = np.concatenate((raw, refine_quats(raw, geometries, offsets)))
    translations = np.concatenate((motion.translations[rows],) * 2)
    known = model.frame != "canonical" or (not mapping and rig_key(motion) in model.rig_frames)
    if known:
        rows_motion = Motion(motion.skeleton, stacked, translations, motion.fps)
        ignore = None
        head = 0
    else:
        # Frames of a rig the model has not seen come from the take's own frames (at most
        # 4,000 evenly spaced, as the limits check samples them) without the frames inside
        # intervals; the rows to read follow them and are left out of that estimate too.
        inside = np.zeros(motion.n_frames, dtype=bool)
        inside[rows] = True
        sample = pose_sample(motion.n_frames)
        sample = np.arange(motion.n_frames) if sample is None else sample
        rows_motion = Motion(
            motion.skeleton,
            np.concatenate((motion.quats[sample], stacked)),
            np.concatenate((motion.translations[sample], translations)),
            motion.fps,
        )
        ignore = np.ones(rows_motion.quats.shape[:2], dtype=bool)
        ignore[: len(sample)] = inside[sample, None]
        head = len(sample)
    try:
        params, columns, _, names = charted(rows_motion, model, mapping, ignore)
    except (LimitsFileError, InputError):
        return AnatomyEvidence.empty(n)
    params = params[head:]
    column = {name: k for k, name in enumerate(names)}
    skeleton = motion.skeleton
    m = len(rows)
    depth_raw = np.full(m, -np.inf)
    depth_fixed = np.full(m, -np.inf)
    child_raw = np.zeros(m)
    child_fixed = np.zeros(m)
    checked = np.zeros(n, dtype=bool)
    for c, geometry in enumerate(geometries):
        mine = chain_of[block] == c
        if not mine.any():
            continue
        parent = column.get(skeleton.names[geometry.chain.parent])
        child = column.get(skeleton.names[geometry.chain.child])
        both = np.concatenate((mine, mine))
        if parent is not None:
            # Signed distance of the twist to the edge of its range (negative inside), degrees.
            read = params[both, parent]
            centre, half = twist_bounds(model.joints[columns[parent]].occupancy, read)
            depth = np.rad2deg(np.abs(wrap(read[:, 2] - centre)) - half)
            depth_raw[mine], depth_fixed[mine] = depth[: mine.sum()], depth[mine.sum() :]
            checked[chain_of == c] = True
        if child is not None:
            _, swing, twist, _ = evaluate(
                model.joints[columns[child]].occupancy, params[both, child]
            )
            distance = np.hypot(swing, twist)
            child_raw[mine], child_fixed[mine] = distance[: mine.sum()], distance[mine.sum() :]
    reduce = np.maximum.reduceat
    inward = checked[block]
    return AnatomyEvidence(
        raw_deg=reduce(np.maximum(depth_raw, 0.0), starts),
        fixed_deg=reduce(np.maximum(depth_fixed, 0.0), starts),
        outward_deg=reduce(np.where(inward, depth_fixed - depth_raw, 0.0), starts),
        child_raw_deg=reduce(child_raw, starts),
        child_fixed_deg=reduce(child_fixed, starts),
        checked=checked,
    )
