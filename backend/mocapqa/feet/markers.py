"""Foot points of a marker take (C3D): heel and toe markers found by name.

Conventions
-----------
* Labels are read without their subject prefix (``TakeoMonday:LHEE`` → ``LHEE``) and split into
  a side and the rest by :func:`mocapqa.core.rig_names.split_side` (``LHEE`` → left, ``hee``;
  ``L_Heel`` → left, ``heel``). The rest is matched exactly against :data:`MARKER_TOKENS`, in
  the order listed; the first role token a side has wins.
* Sets covered: Plug-in Gait and CMU 41 (``LHEE``, ``LTOE``, ``LANK``, ``LKNE``, ``LASI``,
  ``LPSI``, ``LFWT``, ``LBWT``), Vicon full body (``LHEL``, ``LHIP``), anatomical sets
  (``LCAL`` calcaneus, ``LMT1``/``LMT2``/``LMT5`` metatarsal heads, ``LHAL`` hallux, ``LMM``/
  ``LML`` malleoli, ``LCL`` lateral condyle, ``LEAS``/``LEPS`` iliac spines), and
  numbered clusters (``LFT1``…, ``LSK1``…, ``PV1``…).
* Per foot the rear point is the heel marker (part ``"heel"``), else the ankle marker (part
  ``"ankle"``); the front point the toe marker (part ``"toe"``). A foot cluster without named
  markers gives its two markers farthest apart (the foot's long axis), the one nearer the shank
  cluster's centre as the heel and the other as the toe.
* Leg length: the median over frames and sides of pelvis-front marker (ASIS, front waist) →
  knee → ankle where the set has them, which reads a few percent longer than hip joint →
  knee → ankle (the ASIS sits above and in front of the hip joint). Otherwise the 90th
  percentile over frames of the distance from the pelvis markers' centre to each foot's rear
  marker (the leg at its most extended, plus the heel's height). Either way a fixed fraction
  of the body size, which is all the thresholds need.
"""

from __future__ import annotations

import warnings

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.rig_names import split_side
from mocapqa.errors import InputError
from mocapqa.feet.params import FeetParams
from mocapqa.feet.points import SIDES, FootPoints

__all__ = [
    "CLUSTER_TOKENS",
    "MARKER_PARAMS",
    "MARKER_TOKENS",
    "marker_foot_points",
    "marker_label",
]

MARKER_PARAMS = FeetParams(
    release_speed=0.8,
    event_before_s=0.04,
    event_after_s=0.04,
    sole_depth=0.0,
    skate_travel=0.022,
)
"""Thresholds for marker takes. The contact thresholds, smoothing window and event window are
those ``mocapqa bench feet`` chose against the force plates of the corpus's C3D gait trials (on
all of them; each trial's figures are with the values chosen on the others, docs/feet.md): a
toe marker on the forefoot rolls with the foot before the toe leaves the plate (a release
speed of 0.8 leg/s, not 0.6), and each contact's first frame moves to the heel's impact and
its last to the toe's push-off within 0.04 s of them (:mod:`mocapqa.feet.events`). The skate
threshold and sole depth chosen on BVH joints do not carry over: markers sit on the shoe, not
a joint's depth above the sole, so ``sole_depth`` is 0, and ``skate_travel`` keeps its earlier
0.022 leg (at 0.014 with a 0.06 sole the clean flat-foot gait trial had a skate on every one
of its 7 contacts). There is no injected-slide bench on marker takes."""

MARKER_TOKENS: dict[str, tuple[str, ...]] = {
    "heel": ("hee", "heel", "hel", "cal", "calc", "fcc"),
    "toe": ("toe", "toes", "mt2", "fm2", "mh2", "mt1", "fm1", "mh1", "hal", "hx", "mt5", "fm5"),
    "ankle": ("ank", "ankle", "lmal", "mal", "ml", "mm"),
    "knee": ("kne", "knee", "lfe", "lfc", "cl"),
    "pelvis_front": ("asi", "asis", "fwt", "eas", "ias", "hip"),
    "pelvis_back": ("psi", "psis", "bwt", "eps", "ips"),
}
"""Sided marker names (the rest after the side, lower case), by role; the first found wins."""
CLUSTER_TOKENS: dict[str, tuple[str, ...]] = {
    "foot": ("ft", "foot", "fo"),
    "shank": ("sk", "shank", "sh", "tb"),
    "pelvis": ("pv", "pelvis", "sacr", "sacrum", "sac"),
}
"""Numbered cluster markers (``RFT1``, ``PV2``), by segment: the rest without trailing digits."""


def marker_label(name: str) -> str:
    """A marker label without its subject prefix (``"Bob:LANK"`` → ``"LANK"``)."""
    return name.rsplit(":", 1)[-1].strip()


def _roles(names: tuple[str, ...]) -> tuple[dict[tuple[str, str], int], dict[str, list[int]]]:
    """(side, role) → marker index, and cluster segment (``"left foot"``, ``"pelvis"``) →
    marker indices."""
    by_rest: dict[tuple[str | None, str], int] = {}
    clusters: dict[str, list[int]] = {}
    for index, name in enumerate(names):
        side, rest = split_side(marker_label(name))
        by_rest.setdefault((side, rest), index)
        stem = rest.rstrip("0123456789")
        for segment, tokens in CLUSTER_TOKENS.items():
            if stem in tokens:
                key = segment if segment == "pelvis" or side is None else f"{side} {segment}"
                clusters.setdefault(key, []).append(index)
    found: dict[tuple[str, str], int] = {}
    for side in SIDES:
        for role, tokens in MARKER_TOKENS.items():
            for token in tokens:
                if (side, token) in by_rest:
                    found[(side, role)] = by_rest[(side, token)]
                    break
    return found, clusters


def _nanmedian(values: FloatArray) -> float:
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else float("nan")


def _nanmean_points(positions: FloatArray, indices: list[int]) -> FloatArray:
    """Mean position ``(F, 3)`` of some markers, NaN-aware (NaN where all are missing)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean: FloatArray = np.nanmean(positions[:, indices], axis=1)
    return mean


def _cluster_ends(
    positions: FloatArray, foot: list[int], shank: list[int], pelvis: FloatArray | None
) -> tuple[int, int]:
    """Heel and toe of a foot cluster ``(F, M, 3)``: the two markers lowest on the foot
    (farthest from the pelvis centre, median over frames; the first two when there is no
    pelvis), the heel the one nearer the shank cluster's centre."""
    if pelvis is not None and len(foot) > 2:
        reach = [_nanmedian(np.linalg.norm(positions[:, m] - pelvis, axis=-1)) for m in foot]
        order = np.argsort(-np.nan_to_num(np.asarray(reach), nan=-np.inf), kind="stable")
        a, b = foot[int(order[0])], foot[int(order[1])]
    else:
        a, b = foot[0], foot[1]
    if not shank:
        return a, b
    centre = _nanmean_points(positions, shank)
    near_a = _nanmedian(np.linalg.norm(positions[:, a] - centre, axis=-1))
    near_b = _nanmedian(np.linalg.norm(positions[:, b] - centre, axis=-1))
    return (a, b) if near_a <= near_b else (b, a)


def _chosen_points(
    positions: FloatArray,
    names: tuple[str, ...],
    roles: dict[tuple[str, str], int],
    clusters: dict[str, list[int]],
    pelvis: FloatArray | None,
) -> dict[str, list[tuple[int, str]]]:
    """Per foot, (marker, part) of its rear point (heel or ankle) then its toe, by name or
    from a foot cluster.

    Raises
    ------
    InputError
        If a foot has none.
    """
    chosen: dict[str, list[tuple[int, str]]] = {}
    for side in SIDES:
        rear = next(((roles[(side, r)], r) for r in ("heel", "ankle") if (side, r) in roles), None)
        toe = roles.get((side, "toe"))
        if rear is None and toe is None and len(clusters.get(f"{side} foot", [])) >= 2:
            heel, tip = _cluster_ends(
                positions, clusters[f"{side} foot"], clusters.get(f"{side} shank", []), pelvis
            )
            rear, toe = (heel, "heel"), tip
        chosen[side] = ([rear] if rear is not None else []) + (
            [(toe, "toe")] if toe is not None else []
        )
    missing = [side for side in SIDES if not chosen[side]]
    if missing:
        shown = ", ".join(marker_label(n) for n in names[:12]) + (
            ", ..." if len(names) > 12 else ""
        )
        raise InputError(
            f"Expected heel, toe or ankle markers on both feet (Plug-in Gait and CMU LHEE, "
            f"LTOE, LANK; Vicon LHEL; LCAL, LMT1, LHAL; a foot cluster LFT1, LFT2, ...), got "
            f"none for the {' and '.join(missing)} foot among the take's {len(names)} markers"
            f"{': ' + shown if names else ''}"
        )
    return chosen


def _leg_length(
    positions: FloatArray,
    roles: dict[tuple[str, str], int],
    chosen: dict[str, list[tuple[int, str]]],
    pelvis: FloatArray | None,
) -> float:
    """Median pelvis-front → knee → ankle over frames and sides, else the 90th percentile of
    the pelvis-to-rear-point distance, file units.

    Raises
    ------
    InputError
        If neither gives a length > 0.
    """
    legs = [
        np.linalg.norm(
            positions[:, roles[(s, "pelvis_front")]] - positions[:, roles[(s, "knee")]], axis=-1
        )
        + np.linalg.norm(
            positions[:, roles[(s, "knee")]] - positions[:, roles[(s, "ankle")]], axis=-1
        )
        for s in SIDES
        if all((s, r) in roles for r in ("pelvis_front", "knee", "ankle"))
    ]
    if legs:
        leg_length = _nanmedian(np.concatenate(legs))
    elif pelvis is not None:
        reach = np.concatenate(
            [np.linalg.norm(positions[:, chosen[s][0][0]] - pelvis, axis=-1) for s in SIDES]
        )
        finite = reach[np.isfinite(reach)]
        leg_length = float(np.percentile(finite, 90)) if finite.size else float("nan")
    else:
        leg_length = float("nan")
    if not leg_length > 0:
        raise InputError(
            "Expected pelvis markers (LASI/RASI, LPSI/RPSI, LFWT/LBWT, a PV cluster) that give "
            "a leg length > 0, got "
            + ("none" if pelvis is None else f"a leg length of {leg_length} (markers not moving?)")
        )
    return leg_length


def marker_foot_points(sequence: KeypointSequence) -> FootPoints:
    """The foot points of a marker take.

    Parameters
    ----------
    sequence : KeypointSequence
        Marker positions ``(F, M, 3)``, the take's unit, NaN where missing.

    Returns
    -------
    FootPoints
        Per foot the heel (or ankle) marker, then the toe marker where there is one.

    Raises
    ------
    InputError
        If a foot has no heel, ankle, toe or foot-cluster marker, or the set has no pelvis
        markers to measure a leg length from.
    """
    names = sequence.names
    roles, clusters = _roles(names)
    positions = sequence.positions
    front = [roles[(s, "pelvis_front")] for s in SIDES if (s, "pelvis_front") in roles]
    pelvis_markers = (
        front
        + [roles[(s, "pelvis_back")] for s in SIDES if (s, "pelvis_back") in roles]
        + clusters.get("pelvis", [])
    )
    pelvis = _nanmean_points(positions, pelvis_markers) if pelvis_markers else None
    chosen = _chosen_points(positions, names, roles, clusters, pelvis)
    leg_length = _leg_length(positions, roles, chosen, pelvis)
    indices = [i for s in SIDES for i, _ in chosen[s]]
    return FootPoints(
        positions=positions[:, indices],
        sides=tuple(s for s in SIDES for _ in chosen[s]),
        parts=tuple(part for s in SIDES for _, part in chosen[s]),
        names=tuple(names[i] for i in indices),
        fps=sequence.fps,
        leg_length=leg_length,
        length_unit=sequence.length_unit,
        pelvis=pelvis if pelvis is not None and np.isfinite(pelvis).any() else None,
        confidence=sequence.confidence[:, indices],
    )
