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

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError, LimitsFileError
from mocapqa.twist.angles import ChainGeometry
from mocapqa.twist.chain_events import DetectedInterval
from mocapqa.twist.refine import refine_quats

if TYPE_CHECKING:
    from mocapqa.limits.model import LimitsModel
    from mocapqa.limits.occupancy import OccupancyMap

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
    from mocapqa.limits.canonical import rig_key

    n = len(found)
    if n == 0:
        return AnatomyEvidence.empty(0)
    model = _model_for(motion, mapping) if model is None else model
    if model is None:
        return AnatomyEvidence.empty(n)
    rows, block, starts = _interval_rows(found)
    chain_of = np.array([i.chain for i in found], dtype=np.intp)
    # Each interval's block of rows, with its own levels only, on its own chain.
    offsets = np.zeros((len(rows), len(geometries)))
    offsets[np.arange(len(rows)), chain_of[block]] = detected[rows, chain_of[block]]
    raw = motion.quats[rows]
    stacked = np.concatenate((raw, refine_quats(raw, geometries, offsets)))
    known = model.frame != "canonical" or (not mapping and rig_key(motion) in model.rig_frames)
    rows_motion, ignore, head = _rows_motion(motion, rows, stacked, known)
    try:
        params, columns, _, names = charted(rows_motion, model, mapping, ignore)
    except (LimitsFileError, InputError):
        return AnatomyEvidence.empty(n)
    readings = _Readings.of_rows(len(rows), n)
    column = {name: k for k, name in enumerate(names)}
    skeleton = motion.skeleton
    for c, geometry in enumerate(geometries):
        mine = chain_of[block] == c
        if not mine.any():
            continue
        parent, child = (
            _grid(model, columns, column.get(skeleton.names[j]))
            for j in (geometry.chain.parent, geometry.chain.child)
        )
        readings.read_chain(params[head:], mine, chain_of == c, parent, child)
    reduce = np.maximum.reduceat
    inward = readings.checked[block]
    return AnatomyEvidence(
        raw_deg=reduce(np.maximum(readings.depth_raw, 0.0), starts),
        fixed_deg=reduce(np.maximum(readings.depth_fixed, 0.0), starts),
        outward_deg=reduce(
            np.where(inward, readings.depth_fixed - readings.depth_raw, 0.0), starts
        ),
        child_raw_deg=reduce(readings.child_raw, starts),
        child_fixed_deg=reduce(readings.child_fixed, starts),
        checked=readings.checked,
    )


def _interval_rows(found: Sequence[DetectedInterval]) -> tuple[IntArray, IntArray, IntArray]:
    """The frames of every interval one after the other (shape (R,)), the interval of each
    (shape (R,)) and where each interval's block starts (shape (N,))."""
    lengths = np.array([i.end_frame - i.start_frame + 1 for i in found], dtype=np.intp)
    starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    block = np.repeat(np.arange(len(found)), lengths)
    first = np.array([i.start_frame for i in found], dtype=np.intp)
    rows = first[block] + np.arange(len(block)) - starts[block]
    return rows, block, starts


def _grid(model: LimitsModel, columns: list[int], k: int | None) -> tuple[int, OccupancyMap] | None:
    """Column ``k`` of a charted take and its joint's occupancy grid; None for None."""
    return None if k is None else (k, model.joints[columns[k]].occupancy)


def _rows_motion(
    motion: Motion, rows: IntArray, stacked: FloatArray, known: bool
) -> tuple[Motion, BoolArray | None, int]:
    """The take's ``rows`` as read and as corrected (``stacked``, ``(2R, J, 4)``) as a motion to
    chart, the frames that must not set its canonical frames, and how many leading frames to
    drop from its reading.

    Frames of a rig the model has not seen (``known`` False) come from the take's own frames
    (at most 4,000 evenly spaced, as the limits check samples them) without the frames inside
    intervals; the rows to read follow them and are left out of that estimate too.
    """
    from mocapqa.limits.canonical import pose_sample

    translations = np.concatenate((motion.translations[rows],) * 2)
    if known:
        return Motion(motion.skeleton, stacked, translations, motion.fps), None, 0
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
    return rows_motion, ignore, len(sample)


@dataclass(frozen=True, slots=True)
class _Readings:
    """Per row of the intervals (shape (R,)): the parent's twist depth beyond its range raw and
    corrected (degrees, negative inside, -inf unread) and the child's distance outside its
    range raw and corrected (degrees); per interval (shape (N,)): whether its parent was read.
    """

    depth_raw: FloatArray
    depth_fixed: FloatArray
    child_raw: FloatArray
    child_fixed: FloatArray
    checked: BoolArray

    @classmethod
    def of_rows(cls, m: int, n: int) -> _Readings:
        """Nothing read yet, for ``m`` rows of ``n`` intervals."""
        return cls(
            np.full(m, -np.inf), np.full(m, -np.inf), np.zeros(m), np.zeros(m),
            np.zeros(n, dtype=bool),
        )  # fmt: skip

    def read_chain(
        self,
        params: FloatArray,
        mine: BoolArray,
        intervals: BoolArray,
        parent: tuple[int, OccupancyMap] | None,
        child: tuple[int, OccupancyMap] | None,
    ) -> None:
        """Read one chain's rows ``mine`` (R,) from ``params`` ``(2R, K, 3)`` (raw rows then
        corrected ones): its parent's and its child's column and occupancy grid (None: not in
        the model); mark its ``intervals`` (N,) checked when its parent is read."""
        from mocapqa.limits.intervals import wrap
        from mocapqa.limits.occupancy import evaluate, twist_bounds

        both = np.concatenate((mine, mine))
        count = mine.sum()
        if parent is not None:
            # Signed distance of the twist to the edge of its range (negative inside), degrees.
            read = params[both, parent[0]]
            centre, half = twist_bounds(parent[1], read)
            depth = np.rad2deg(np.abs(wrap(read[:, 2] - centre)) - half)
            self.depth_raw[mine], self.depth_fixed[mine] = depth[:count], depth[count:]
            self.checked[intervals] = True
        if child is not None:
            _, swing, twist, _ = evaluate(child[1], params[both, child[0]])
            distance = np.hypot(swing, twist)
            self.child_raw[mine], self.child_fixed[mine] = distance[:count], distance[count:]
