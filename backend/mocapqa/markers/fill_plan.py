"""Every method's fill of one gap and its cross-validated error on the take's own samples.

The gap's length is hidden again in stretches where the same marker is recorded (and the same
donor and model markers are visible): half of the trials nearest to the gap, half spread over the
take (``FillParams.cv_local``). Each method fills them; its RMSE over the hidden samples (3-D
distance, root mean square) is its expected error for the gap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.markers.fill_methods import rigid_fill, spline_fill
from mocapqa.markers.fill_params import METHODS, FillParams
from mocapqa.markers.fill_pca import PcaModel, pca_fill, pca_model

__all__ = ["FillContext", "GapPlan", "plan_gap"]


@dataclass(frozen=True, slots=True)
class GapPlan:
    """Every method's fill of one gap with its cross-validated error (see :func:`plan_gap`).

    Parameters
    ----------
    fills : dict of str to ndarray, shape (L, 3)
        Each method's fill of the gap (methods that cannot fill it are absent).
    errors : dict of str to float
        Each tried method's cross-validated RMSE in the take's unit (NaN: no trial possible).
    donors : ndarray of int
        The rigid fill's donors.
    model : ndarray of int
        The PCA fill's other markers.
    """

    fills: dict[str, FloatArray]
    errors: dict[str, float]
    donors: IntArray
    model: IntArray

    def best(self) -> tuple[str | None, float]:
        """The method with the lowest finite error among those that filled, and that error."""
        best: tuple[str | None, float] = (None, float("nan"))
        for name in METHODS:
            err = self.errors.get(name, float("nan"))
            if name in self.fills and np.isfinite(err) and not err >= best[1]:
                best = (name, err)
        return best


class FillContext:
    """A take, its visibility and the settings in frames and file units, shared by its gaps.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Marker positions in the file's unit, NaN where missing (not copied: do not modify).
    fps : float
        Frame rate (Hz).
    params : FillParams
        Settings (lengths in mm, times in seconds).
    scale : float
        File units per mm.

    Notes
    -----
    Each marker's distance statistics (:meth:`distance_stats`) are computed on first use.
    """

    def __init__(self, positions: FloatArray, fps: float, params: FillParams, scale: float):
        self.positions = positions
        self.visible: BoolArray = np.asarray(~np.isnan(positions).any(axis=2))
        self.n = positions.shape[0]
        self.params = params
        self.spline_window = max(2, round(params.spline_window_s * fps))
        self.spline_max = max(1, round(params.spline_max_gap_s * fps))
        self.rigid_window = max(1, round(params.rigid_window_s * fps))
        self.max_std = params.rigid_max_std_mm * scale
        self.min_spread = params.rigid_min_spread_mm * scale
        self.weight_scale = params.pca_weight_mm * scale
        self._stats: dict[int, tuple[FloatArray, FloatArray]] = {}

    def distance_stats(self, m: int) -> tuple[FloatArray, FloatArray]:
        """Mean and standard deviation of each marker's distance to marker ``m``, shape (M,).

        Over the frames where both are visible; infinite for ``m`` itself and for markers seen
        together with it on fewer than ten frames.
        """
        if m not in self._stats:
            rows = np.flatnonzero(self.visible[:, m])
            if rows.size > 4000:
                rows = rows[np.linspace(0, rows.size - 1, 4000).round().astype(np.intp)]
            d = np.linalg.norm(self.positions[rows] - self.positions[rows, m][:, None], axis=2)
            ok = self.visible[rows]
            count = ok.sum(axis=0)
            d0 = np.where(ok, d, 0.0)
            mean = d0.sum(axis=0) / np.maximum(count, 1)
            var = np.where(ok, (d0 - mean) ** 2, 0.0).sum(axis=0) / np.maximum(count, 1)
            bad = count < 10
            bad[m] = True
            mean[bad] = np.inf
            std = np.sqrt(var)
            std[bad] = np.inf
            self._stats[m] = (mean, std)
        return self._stats[m]


def _fill(
    take: FillContext,
    name: str,
    m: int,
    a: int,
    b: int,
    donors: IntArray,
    model: IntArray,
    before: bool,
    after: bool,
    hidden: tuple[int, int] | None = None,
    fitted: PcaModel | None = None,
) -> FloatArray | None:
    p, v = take.positions, take.visible
    if name == "spline":
        return spline_fill(
            p, v, m, a, b, window=take.spline_window, max_length=take.spline_max,
            before=before, after=after,
        )  # fmt: skip
    if name == "rigid":
        return rigid_fill(
            p, v, m, a, b, donors, window=take.rigid_window, smooth=take.params.smooth_anchor,
            before=before, after=after,
        )  # fmt: skip
    return pca_fill(
        p, v, m, a, b, model,
        weight_scale=take.weight_scale, variance=take.params.pca_variance,
        max_train=take.params.pca_max_train, window=take.rigid_window,
        smooth=take.params.smooth_anchor, hidden=hidden, fitted=fitted,
        before=before, after=after,
    )  # fmt: skip


def _model_markers(take: FillContext, m: int, candidates: IntArray, a: int, b: int) -> IntArray:
    """The PCA fill's markers: nearest candidates, thinned until enough frames train it."""
    mean, _ = take.distance_stats(m)
    order = candidates[np.argsort(mean[candidates], kind="stable")]
    model = order[np.isfinite(mean[order])][: take.params.pca_markers]
    rows = take.visible[:, m].copy()
    rows[a : b + 1] = False
    while model.size > 3:
        ok = take.visible[rows][:, model]
        if ok.all(axis=1).sum() >= max(4 * (3 * model.size + 3), 60):
            break
        model = np.delete(model, int(np.argmin(ok.sum(axis=0))))
    return model.astype(np.intp)


def _donors(take: FillContext, ranked: IntArray, frame: int) -> IntArray:
    """The rigid fill's donors: the steadiest candidates that span a plane.

    The first is the steadiest; the second the steadiest at least ``rigid_min_spread_mm`` from
    it; the third the steadiest as far from the line through both; further ones by steadiness.
    Fewer than three when no candidates span a plane (their rotation about the line would be
    unknown).
    """
    if ranked.size < 3:
        return np.empty(0, dtype=np.intp)
    xyz = take.positions[frame, ranked]
    first = xyz[0]
    far = np.flatnonzero(np.linalg.norm(xyz - first, axis=1) >= take.min_spread)
    if far.size == 0:
        return np.empty(0, dtype=np.intp)
    second = int(far[0])
    axis = (xyz[second] - first) / np.linalg.norm(xyz[second] - first)
    rel = xyz - first
    off_line = np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)
    wide = np.flatnonzero(off_line >= take.min_spread)
    if wide.size == 0:
        return np.empty(0, dtype=np.intp)
    third = int(wide[0])
    chosen = [0, second, third]
    rest = [i for i in range(ranked.size) if i not in chosen]
    chosen += rest[: take.params.rigid_donors - 3]
    return ranked[np.array(chosen, dtype=np.intp)]


def _trial_starts(
    ok: BoolArray, length: int, lead: int, tail: int, trials: int, near: int, local: bool
) -> IntArray:
    """Up to ``trials`` starts ``s`` with ``ok`` over ``s - lead .. s + length - 1 + tail``.

    With ``local``, the starts nearest to frame ``near``, at most one per block of ``length``
    frames (so they hardly overlap); otherwise evenly spread over the take.
    """
    width = lead + length + tail
    if width > ok.size:
        return np.empty(0, dtype=np.intp)
    c = np.concatenate(([0], np.cumsum(ok, dtype=np.int64)))
    starts = np.flatnonzero(c[width:] - c[:-width] == width) + lead
    if starts.size == 0 or not local:
        pick = np.unique(np.linspace(0, starts.size - 1, min(trials, starts.size)).round())
        return starts[pick.astype(np.intp)].astype(np.intp)
    by_distance = starts[np.argsort(np.abs(starts - near), kind="stable")]
    _, first = np.unique(by_distance // length, return_index=True)
    nearest = by_distance[np.sort(first)[: (trials + 1) // 2]]
    spread = starts[
        np.linspace(0, starts.size - 1, min(trials, starts.size)).round().astype(np.intp)
    ]
    spread = spread[~np.isin(spread, nearest)][: trials - nearest.size]
    return np.sort(np.concatenate((nearest, spread))).astype(np.intp)


def plan_gap(take: FillContext, m: int, a: int, b: int) -> GapPlan:
    """Fill one gap by every method and cross-validate each on the take's own samples.

    Parameters
    ----------
    take : FillContext
        The take (positions ``(F, M, 3)`` in file units, NaN where missing).
    m, a, b : int
        Marker index and first and last missing frame (inclusive).

    Returns
    -------
    GapPlan
    """
    params = take.params
    vis = take.visible
    before, after = a > 0, b < take.n - 1
    lo, hi = (a - 1 if before else a), (b + 1 if after else b)
    candidates = np.flatnonzero(vis[lo : hi + 1].all(axis=0))
    candidates = candidates[candidates != m]
    _, std = take.distance_stats(m)
    ranked = candidates[np.argsort(std[candidates], kind="stable")]
    donors = _donors(take, ranked[std[ranked] <= take.max_std], lo if before else hi)
    model = _model_markers(take, m, candidates, a, b)

    fitted = None
    if "pca" in params.methods:
        # One training matrix serves the gap and its trials (each trial's frames are taken out
        # of it; only the normalisation keeps them, a negligible share of the training frames).
        fitted = pca_model(
            take.positions, vis, m, model,
            exclude=(a, b), weight_scale=take.weight_scale, max_train=params.pca_max_train,
        )  # fmt: skip
    fills: dict[str, FloatArray] = {}
    for name in params.methods:
        if name == "pca" and fitted is None:
            continue
        filled = _fill(take, name, m, a, b, donors, model, before, after, fitted=fitted)
        if filled is not None:
            fills[name] = filled
    length = b - a + 1
    lead, tail = (2 if before else 0), (2 if after else 0)
    need = {
        "spline": vis[:, m],
        "rigid": vis[:, m] & vis[:, donors].all(axis=1),
        "pca": vis[:, m] & vis[:, model].all(axis=1),
    }
    common = np.logical_and.reduce([need[name] for name in fills]) if fills else vis[:, m]

    def trial_starts(ok: BoolArray) -> IntArray:
        return _trial_starts(ok, length, lead, tail, params.cv_trials, a, params.cv_local)

    shared = trial_starts(common)
    errors: dict[str, float] = {}
    for name in fills:
        starts = shared
        if starts.size == 0:
            starts = trial_starts(need[name])
        sq, count = 0.0, 0
        for s in starts.tolist():
            e = s + length - 1
            trial = _fill(
                take, name, m, s, e, donors, model, before, after, hidden=(s, e), fitted=fitted
            )
            if trial is not None:
                sq += float(np.sum((trial - take.positions[s : e + 1, m]) ** 2))
                count += length
        errors[name] = float(np.sqrt(sq / count)) if count else float("nan")
    return GapPlan(fills=fills, errors=errors, donors=donors, model=model)
