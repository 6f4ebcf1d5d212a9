"""Foot pinning on keypoint and marker takes: every keypoint (marker) of a foot moves
horizontally by the lock's offset (:mod:`mocapqa.feet.lock`) during the chosen contacts,
blended in and out; missing samples stay missing."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.rig_names import split_side, token_of
from mocapqa.feet.ground import UpAxis
from mocapqa.feet.lock import BLEND_S, Anchor, Lock, lock_offsets, pivot_steps, planted_travel
from mocapqa.feet.markers import CLUSTER_TOKENS, MARKER_TOKENS, marker_label
from mocapqa.feet.points import SIDES, FootPoints
from mocapqa.feet.tracks import horizontal_axes

__all__ = [
    "FOOT_MARKER_ROLES",
    "FOOT_TOKENS",
    "PinResult",
    "foot_keypoints",
    "marker_foot_members",
    "pin_feet",
]

FOOT_TOKENS = frozenset({"ankle", "heel", "bigtoe", "smalltoe", "footindex", "toe", "toes"})
"""Name tokens (after the side, :func:`mocapqa.core.rig_names.split_side`) of the keypoints a
pin moves with the foot: ankle, heel and toes."""


def foot_keypoints(
    names: Sequence[str], point_names: Sequence[str], point_sides: Sequence[str]
) -> tuple[list[list[int]], list[list[int]]]:
    """The keypoints of each foot, for pinning.

    Parameters
    ----------
    names : sequence of str
        The take's keypoint names.
    point_names, point_sides : sequence of str
        The feet check's foot points (:class:`mocapqa.feet.points.FootPoints` ``names`` and
        ``sides``): per side the rear point, then the toe when there is one.

    Returns
    -------
    points : list of list of int
        Per side (left, right), the indices of its foot points in ``names``.
    members : list of list of int
        Per side, every keypoint moved with the foot: the foot points and the keypoints of that
        side named by :data:`FOOT_TOKENS`.
    """
    index = {name: i for i, name in reversed(list(enumerate(names)))}
    points = [
        [index[n] for n, s in zip(point_names, point_sides, strict=True) if s == side]
        for side in SIDES
    ]
    members = []
    for side, own in zip(SIDES, points, strict=True):
        named = []
        for i, name in enumerate(names):
            named_side, rest = split_side(name)
            if named_side == side and token_of(rest) in FOOT_TOKENS:
                named.append(i)
        members.append(sorted(set(own) | set(named)))
    return points, members


FOOT_MARKER_ROLES = ("heel", "toe", "ankle")
"""The roles of :data:`mocapqa.feet.markers.MARKER_TOKENS` whose markers move with a pinned
foot (with the markers of a foot cluster, ``LFT1``…)."""


def marker_foot_members(
    names: Sequence[str], points: FootPoints
) -> tuple[list[list[int]], list[list[int]]]:
    """The foot points of a marker take and, per foot, every marker pinned with it.

    Parameters
    ----------
    names : sequence of str
        The take's marker names (subject prefixes allowed).
    points : FootPoints
        The feet check's (:func:`mocapqa.feet.markers.marker_foot_points`).

    Returns
    -------
    points : list of list of int
        Per side (left, right), the indices of its foot points in ``names``.
    members : list of list of int
        Per side, the foot points and the markers of that side whose label (without a subject
        prefix) names a heel, toe or ankle (:data:`FOOT_MARKER_ROLES`) or a foot cluster.
    """
    own, _ = foot_keypoints(names, points.names, points.sides)
    tokens = {t for role in FOOT_MARKER_ROLES for t in MARKER_TOKENS[role]}
    members = []
    for side, indices in zip(SIDES, own, strict=True):
        named = set(indices)
        for index, name in enumerate(names):
            named_side, rest = split_side(marker_label(name))
            if named_side == side and (
                rest in tokens or rest.rstrip("0123456789") in CLUSTER_TOKENS["foot"]
            ):
                named.add(index)
        members.append(sorted(named))
    return own, members


@dataclass(frozen=True, slots=True)
class PinResult:
    """Pinned keypoints and what the pin did.

    Parameters
    ----------
    positions : ndarray, shape (F, K, 3)
        The take's keypoints with the locks applied, take units (NaN stays NaN).
    changed : ndarray of bool, shape (F, 2)
        Frames where the left and right foot were moved (contacts and their blends).
    before, after : ndarray, shape (L,)
        Per contact measured, the pivot's planted travel in the input and the result, take
        units.
    """

    positions: FloatArray
    changed: BoolArray
    before: FloatArray
    after: FloatArray


def pin_feet(
    positions: FloatArray,
    points: Sequence[Sequence[int]],
    members: Sequence[Sequence[int]],
    up: UpAxis,
    locks: Sequence[Lock],
    fps: float,
    plant_speed: float,
    anchor: Anchor = "middle",
    blend_s: float = BLEND_S,
    measure: Sequence[Lock] | None = None,
    depths: FloatArray | None = None,
) -> PinResult:
    """Pin the feet of a keypoint take during the given contacts: every keypoint of a foot
    moves horizontally by the lock's offset (see the module notes), blended in and out.

    Parameters
    ----------
    positions : ndarray, shape (F, K, 3)
        Take units, NaN where missing.
    points : sequence of sequence of int
        Per side (left, right), the rear point and the toe (:func:`foot_keypoints`).
    members : sequence of sequence of int
        Per side, the keypoints moved with the foot.
    up : UpAxis
    locks : sequence of Lock
    fps : float
    plant_speed : float
        Take units per second (:func:`mocapqa.feet.lock.planted_tracks`).
    anchor : {"middle", "start"}
    blend_s : float
    measure : sequence of Lock, optional
        The contacts whose slide is reported (``locks`` when None).
    depths : ndarray, shape (F, P), optional
        Each foot point's height above the sole (:func:`mocapqa.feet.lock.sole_heights`, the
        points of ``points``, left then right), take units: the pin then holds the sole under
        the pivot, what the skate check reads. None holds the points.

    Returns
    -------
    PinResult
    """
    joints = [j for group in points for j in group]
    columns = np.cumsum([0, len(points[0])])
    local = [list(range(c, c + len(g))) for c, g in zip(columns, points, strict=True)]

    def steps_of(values: FloatArray) -> FloatArray:
        return np.nan_to_num(pivot_steps(values[:, joints], local, up, depths))

    steps = steps_of(positions)
    flat, weights = lock_offsets(steps, locks, fps, plant_speed, anchor, blend_s)
    out = np.array(positions, dtype=np.float64, copy=True)
    axes = list(horizontal_axes(up.axis))
    for foot, keypoints in enumerate(members):
        rows = np.flatnonzero(weights[:, foot] > 0)
        block = np.ix_(rows, np.asarray(keypoints, dtype=np.intp), np.asarray(axes, dtype=np.intp))
        out[block] += flat[rows, foot][:, None, :]
    after = steps_of(out)
    measured = locks if measure is None else measure
    before_travel = planted_travel(steps, measured, fps, plant_speed)
    after_travel = planted_travel(after, measured, fps, plant_speed)
    return PinResult(out, weights > 0, before_travel, after_travel)
