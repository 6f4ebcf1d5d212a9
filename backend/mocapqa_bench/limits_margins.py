"""Per-joint twist margins chosen by nested leave-one-rig-out (``mocapqa bench limits
--joint-margins``).

The shipped canonical map widens every twist arc by one margin (40°). Here each role gets its
own margin, chosen without ever looking at the rig it is tested on:

* **outer fold** — leave rig ``R`` out; the margins used on ``R`` are chosen on the other rigs
  only;
* **inner folds** — for each other rig ``R'``, a map (margin 0) built on the rigs other than
  ``R`` and ``R'`` is checked on ``R'`` at every margin of :data:`MARGINS_DEG`; per role, the
  chosen margin is the smallest whose false-flag rate, averaged over the inner left-out rigs,
  is at most ``target`` (1 %: the issue's target, fixed beforehand), else the margin with the
  fewest false flags. The smallest such margin keeps the most injected errors flagged;
* the map built on every rig but ``R`` (margin 0) then gets those margins and is checked on
  ``R``: clean false flags and injected-error recall, as :func:`~mocapqa_bench.limits_canonical.
  count_takes` counts them, beside the uniform 40° on the same map.

The margin is the last step of :func:`~mocapqa.limits.occupancy.build_occupancy` (``half =
min(half + margin, π)``), so a margin-0 map widened here equals a map built with that margin,
and every margin is read from one build per fold. ``005_05`` is in no fold.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mocapqa.core.motion import Motion
from mocapqa.limits.analysis import charted
from mocapqa.limits.build import DEFAULT_BUILD, BuildParams, build_canonical_model
from mocapqa.limits.model import LimitsModel
from mocapqa.limits.occupancy import OccupancyMap, evaluate
from mocapqa.twist.inject import inject_twist_errors
from mocapqa_bench.limits_canonical import EVALUATION_ONLY

__all__ = ["MARGINS_DEG", "FoldResult", "MarginCounts", "count_margins", "nested_margins"]

MARGINS_DEG = (0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0)
"""Candidate twist margins, degrees."""

Takes = tuple[tuple[str, Motion], ...]


def widened(occupancy: OccupancyMap, margin_deg: float) -> OccupancyMap:
    """A margin-0 map with ``margin_deg`` added on both sides of every twist arc."""
    centre = 0.5 * (occupancy.tau_min + occupancy.tau_max)
    half = np.minimum(0.5 * (occupancy.tau_max - occupancy.tau_min) + np.deg2rad(margin_deg), np.pi)
    return OccupancyMap(
        occupancy.bin_deg, occupancy.occupied, centre - half, centre + half, occupancy.interpolate
    )


@dataclass(frozen=True, slots=True)
class MarginCounts:
    """Counts of one map on one rig's takes, at every margin of :data:`MARGINS_DEG`.

    Parameters
    ----------
    roles : tuple of str
    flagged : ndarray of int, shape (M, R)
        Clean flagged frames per margin and role, summed over takes.
    frames : ndarray of int, shape (R,)
        Clean frames per role.
    injected : list of tuple
        Per injected error: ``(valid (M, E, 2) bool, ok (2,) bool, roles (2,) int)``: the
        target's and its child's validity at the error frames per margin, whether each joint
        is checked, and their role columns.
    """

    roles: tuple[str, ...]
    flagged: np.ndarray
    frames: np.ndarray
    injected: list[tuple[np.ndarray, np.ndarray, np.ndarray]]

    def false_flags(self, margins: np.ndarray) -> tuple[float, np.ndarray]:
        """Overall and per-role false-flag rate with margin index ``margins[r]`` per role."""
        per = self.flagged[margins, np.arange(len(self.roles))]
        return float(per.sum() / max(self.frames.sum(), 1)), per / np.maximum(self.frames, 1)

    def recall(self, margins: np.ndarray) -> tuple[int, int]:
        """Flagged and injected error frames with margin index ``margins[r]`` per role."""
        hits = total = 0
        for valid, ok, roles in self.injected:
            found = np.zeros(valid.shape[1], dtype=bool)
            for k in range(2):
                if ok[k]:
                    found |= ~valid[margins[roles[k]], :, k]
            hits += int(found.sum())
            total += valid.shape[1]
        return hits, total


def _validity(model: LimitsModel, motion: Motion) -> tuple[np.ndarray, list[int], list[str]]:
    """Validity ``(M, F, J)`` of the model's joints at each margin, their model columns and
    skeleton joint names."""
    params, columns, _, names = charted(motion, model, None)
    out = np.zeros((len(MARGINS_DEG), params.shape[0], len(columns)), dtype=bool)
    for j, k in enumerate(columns):
        base = model.joints[k].occupancy
        for m, margin in enumerate(MARGINS_DEG):
            out[m, :, j] = evaluate(widened(base, margin), params[:, j])[0]
    return out, list(columns), list(names)


def count_margins(
    model: LimitsModel, takes: Takes, seed: int = 0, min_offset_deg: float = 60.0
) -> MarginCounts:
    """Clean flags and injected-error validity of a margin-0 ``model`` at every margin (the
    same takes, seed and injected errors as :func:`mocapqa_bench.limits_canonical.count_takes`).
    """
    roles = tuple(j.role for j in model.joints)
    rng = np.random.default_rng(seed)
    flagged = np.zeros((len(MARGINS_DEG), len(roles)), dtype=np.int64)
    frames = np.zeros(len(roles), dtype=np.int64)
    injected: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for name, motion in takes:
        if name in EVALUATION_ONLY:
            continue
        valid, columns, _ = _validity(model, motion)
        flagged[:, columns] += (~valid).sum(axis=1)
        frames[columns] += motion.n_frames
        corrupted, truth = inject_twist_errors(
            motion, rng, min_offset_deg=min_offset_deg, max_offset_deg=180.0
        )
        bad, bad_columns, names = _validity(model, corrupted)
        where = {n: j for j, n in enumerate(names)}
        for target, child in zip(truth.targets, truth.children, strict=True):
            rows = np.flatnonzero(truth.error_mask[:, target])
            pair = np.zeros((len(MARGINS_DEG), rows.size, 2), dtype=bool)
            ok = np.zeros(2, dtype=bool)
            role_columns = np.zeros(2, dtype=np.intp)
            for k, joint in enumerate((target, child)):
                j = where.get(motion.skeleton.names[joint])
                if j is not None:
                    pair[:, :, k] = bad[:, rows, j]
                    ok[k] = True
                    role_columns[k] = bad_columns[j]
            injected.append((pair, ok, role_columns))
    return MarginCounts(roles, flagged, frames, injected)


def _map(rigs: dict[str, Takes], left_out: set[str], settings: BuildParams) -> LimitsModel:
    train = [
        t for family, takes in rigs.items() if family not in left_out for t in takes
        if t[0] not in EVALUATION_ONLY
    ]  # fmt: skip
    return build_canonical_model([m for _, m in train], [n for n, _ in train], settings)


def choose_margins(inner: list[MarginCounts], target: float, rule: str = "mean") -> np.ndarray:
    """Per role, the index of the smallest margin whose false-flag rate over the inner
    left-out rigs is ≤ ``target`` (else the one with the fewest): averaged over them
    (``rule="mean"``) or on the worst of them (``"worst"``)."""
    n_roles = len(inner[0].roles)
    if any(counts.roles != inner[0].roles for counts in inner):
        raise ValueError("Expected the inner maps to model the same roles in the same order")
    if rule not in ("mean", "worst"):
        raise ValueError(f"Expected rule 'mean' or 'worst', got {rule!r}")
    each = np.stack([c.flagged / np.maximum(c.frames, 1) for c in inner])
    rates = each.mean(axis=0) if rule == "mean" else each.max(axis=0)
    chosen = np.zeros(n_roles, dtype=np.intp)
    for r in range(n_roles):
        fine = np.flatnonzero(rates[:, r] <= target)
        chosen[r] = fine[0] if fine.size else int(np.argmin(rates[:, r]))
    return chosen


@dataclass(frozen=True, slots=True)
class FoldResult:
    """One outer fold: the chosen margins and the left-out rig's figures."""

    family: str
    margins_deg: dict[str, float]
    false_flags: float
    hits: int
    injected: int
    uniform_false_flags: float
    uniform_hits: int


def nested_margins(
    rigs: dict[str, Takes],
    settings: BuildParams = DEFAULT_BUILD,
    target: float = 0.01,
    uniform_deg: float = 40.0,
    seed: int = 0,
    rule: str = "mean",
) -> list[FoldResult]:
    """Nested leave-one-rig-out choice of per-role twist margins (module notes).

    Parameters
    ----------
    rigs : dict
        Family → every take of that rig (as ``mocapqa bench limits`` groups them).
    settings : BuildParams
        Map setting; its margin is replaced by 0 and the discriminator dropped.
    target : float
        False-flag rate a role's margin must reach on the inner folds.
    uniform_deg : float
        The uniform margin compared against (the shipped 40°).
    rule : {"mean", "worst"}
        How the inner folds' false-flag rates are combined (:func:`choose_margins`).
    """
    base = replace(
        settings,
        occupancy=replace(settings.occupancy, tau_margin_deg=0.0),
        discriminator=None,
    )
    uniform = MARGINS_DEG.index(uniform_deg)
    results = []
    for family in rigs:
        inner = [
            count_margins(_map(rigs, {family, other}, base), rigs[other], seed)
            for other in rigs
            if other != family
        ]
        chosen = choose_margins(inner, target, rule)
        counts = count_margins(_map(rigs, {family}, base), rigs[family], seed)
        flags, _ = counts.false_flags(chosen)
        hits, total = counts.recall(chosen)
        same = np.full(len(counts.roles), uniform)
        uniform_flags, _ = counts.false_flags(same)
        uniform_hits, _ = counts.recall(same)
        margins = {r: MARGINS_DEG[c] for r, c in zip(counts.roles, chosen, strict=True)}
        fold = FoldResult(family, margins, flags, hits, total, uniform_flags, uniform_hits)
        results.append(fold)
    return results
