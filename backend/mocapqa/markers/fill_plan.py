"""Every method's fill of one gap and its cross-validated error on the take's own samples.

The gap's length is hidden again in stretches where the same marker is recorded (and the same
donor and model markers are visible): half of the trials nearest to the gap, the rest where the
markers nearest to the target move as fast as they do over the gap (``FillParams.cv_local``,
``cv_match``; :mod:`mocapqa.markers.fill_cv`). Each method fills them; its RMSE over the hidden
samples (3-D distance, root mean square) is its expected error for the gap. The methods' fills
blended by inverse expected error (``FillParams.blend_power``) are a fourth candidate, ``blend``,
cross-validated on the same stretches with each stretch's weights from the others.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.markers.fill_cv import (
    blend_trial_error,
    blend_weights,
    marker_speed_sums,
    trial_starts,
    window_motion,
)
from mocapqa.markers.fill_methods import rigid_fill, spline_fill
from mocapqa.markers.fill_params import CHOICES, PCA_FAMILY, FillParams
from mocapqa.markers.fill_pca import PcaModel, pca_fill, pca_model

__all__ = ["FillContext", "GapPlan", "plan_gap"]


@dataclass(frozen=True, slots=True)
class GapPlan:
    """Every method's fill of one gap with its cross-validated error (see :func:`plan_gap`).

    Parameters
    ----------
    fills : dict of str to ndarray, shape (L, 3)
        Each method's fill of the gap (methods that cannot fill it are absent), and ``blend``,
        their blend, when two or more have an expected error.
    errors : dict of str to float
        Each tried method's (and the blend's) cross-validated RMSE in the take's unit (NaN: no
        trial possible).
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
        """The method (or ``blend``) with the lowest finite error among those that filled, and
        that error."""
        best: tuple[str | None, float] = (None, float("nan"))
        for name in CHOICES:
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
    Each marker's distance statistics (:meth:`distance_stats`) are computed on first use;
    ``speed_sums`` holds the running sums of every marker's speed
    (:func:`~mocapqa.markers.fill_cv.marker_speed_sums`).
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
        self.speed_sums = marker_speed_sums(positions, self.visible)
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
    """Fill ``a..b`` of marker ``m`` by method ``name`` (a PCA method with its ``fitted``
    training matrix when given)."""
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
        centre=PCA_FAMILY[name],
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


def _motion(
    take: FillContext, m: int, a: int, b: int, donors: IntArray, model: IntArray
) -> tuple[FloatArray, float] | None:
    """The mean speed of the markers nearest to the target over a window of the gap's length
    starting at every frame, and over the gap itself (see :mod:`mocapqa.markers.fill_cv`)."""
    if take.params.cv_match != "motion":
        return None
    near = model[: take.params.cv_motion_markers] if model.size else donors
    if near.size == 0:
        return None
    length = b - a + 1
    every = np.arange(take.n, dtype=np.intp)
    values = window_motion(take.speed_sums, near, every, length)
    gap = float(values[a]) if a + length <= take.n else float("nan")
    return (values, gap) if np.isfinite(gap) else None


@dataclass(slots=True)
class _Trials:
    """Each method's fills of the hidden stretches: starts, fills ``(T, L, 3)`` and truth."""

    starts: list[int]
    fills: list[FloatArray]
    truth: list[FloatArray]

    def rmse(self) -> float:
        if not self.starts:
            return float("nan")
        return float(np.sqrt(np.mean(np.sum((np.stack(self.fills) - np.stack(self.truth)) ** 2,
                                            axis=-1))))  # fmt: skip


def _trial_fill(
    take: FillContext,
    name: str,
    m: int,
    s: int,
    e: int,
    gap: tuple[IntArray, IntArray, bool, bool],
    fitted: PcaModel | None,
) -> FloatArray | None:
    """One method's fill of a hidden stretch ``s..e`` of marker ``m``; the PCA fill drops the
    model markers not seen over it (and refits) rather than give up."""
    donors, model, before, after = gap
    if name in PCA_FAMILY:
        seen = take.visible[s : e + 1][:, model].all(axis=0)
        if not seen.all():
            model, fitted = model[seen], None
            if model.size < 3:
                return None
    return _fill(take, name, m, s, e, donors, model, before, after, hidden=(s, e), fitted=fitted)


def _cross_validate(
    take: FillContext,
    m: int,
    a: int,
    b: int,
    methods: list[str],
    gap: tuple[IntArray, IntArray, bool, bool],
    fitted: dict[str, PcaModel],
) -> dict[str, _Trials]:
    """Each method's fills of up to ``cv_trials`` stretches of the gap's length where marker
    ``m`` is recorded: the same stretches for every method where possible."""
    params, vis = take.params, take.visible
    donors, model, before, after = gap
    length = b - a + 1
    lead, tail = (2 if before else 0), (2 if after else 0)
    need = {"spline": vis[:, m], "rigid": vis[:, m] & vis[:, donors].all(axis=1)}
    # The PCA trials refit without the model markers not seen over them.
    for name in PCA_FAMILY:
        need[name] = vis[:, m] & (vis[:, model].all(axis=1) if model.size else True)
    motion = _motion(take, m, a, b, donors, model)

    def starts_where(ok: BoolArray) -> IntArray:
        return trial_starts(ok, length, lead, tail, params.cv_trials, a,
                            local=params.cv_local, motion=motion)  # fmt: skip

    shared = starts_where(np.logical_and.reduce([need[x] for x in methods]))
    if shared.size == 0:
        shared = starts_where(
            np.logical_and.reduce([need[x] for x in methods if x not in PCA_FAMILY])
        )
    out: dict[str, _Trials] = {}
    for name in methods:
        starts = shared if shared.size else starts_where(need[name])
        if starts.size == 0 and name in PCA_FAMILY:
            starts = starts_where(need["spline"])
        trials = _Trials([], [], [])
        for s in starts.tolist():
            e = s + length - 1
            filled = _trial_fill(take, name, m, s, e, gap, fitted.get(name))
            if filled is not None:
                trials.starts.append(s)
                trials.fills.append(filled)
                trials.truth.append(take.positions[s : e + 1, m])
        out[name] = trials
    return out


def _blend(
    fills: dict[str, FloatArray],
    errors: dict[str, float],
    trials: dict[str, _Trials],
    params: FillParams,
) -> tuple[FloatArray, float] | None:
    """The methods' fills blended by inverse expected error, and the blend's cross-validated
    error on the stretches every blended method filled; None with fewer than two methods."""
    names = [x for x in fills if np.isfinite(errors.get(x, np.nan))]
    if params.blend_power <= 0 or len(names) < 2:
        return None
    common = set.intersection(*(set(trials[x].starts) for x in names))
    if not common:
        return None
    rows = [[trials[x].starts.index(s) for s in sorted(common)] for x in names]
    pairs = zip(names, rows, strict=True)
    stack = np.stack([np.stack([trials[x].fills[i] for i in row]) for x, row in pairs], axis=1)
    truth = np.stack([trials[names[0]].truth[i] for i in rows[0]])
    weights = blend_weights(np.array([errors[x] for x in names]), params.blend_power)
    squared = np.sum((stack - truth[:, None]) ** 2, axis=(2, 3))
    error = blend_trial_error(squared, stack, truth, params.blend_power)
    blended = np.einsum("k,kld->ld", weights, np.stack([fills[x] for x in names]))
    return blended, error


def plan_gap(take: FillContext, m: int, a: int, b: int) -> GapPlan:
    """Fill one gap by every method and their blend, and cross-validate each on the take.

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

    # One training matrix per PCA method serves the gap and its trials (each trial's frames are
    # taken out of it; only the normalisation keeps them, a negligible share of the frames).
    fitted: dict[str, PcaModel] = {}
    for name in params.methods:
        if name in PCA_FAMILY:
            model_fit = pca_model(
                take.positions, vis, m, model,
                exclude=(a, b), weight_scale=take.weight_scale, max_train=params.pca_max_train,
                centre=PCA_FAMILY[name],
            )  # fmt: skip
            if model_fit is not None:
                fitted[name] = model_fit
    fills: dict[str, FloatArray] = {}
    for name in params.methods:
        if name in PCA_FAMILY and name not in fitted:
            continue
        filled = _fill(take, name, m, a, b, donors, model, before, after, fitted=fitted.get(name))
        if filled is not None:
            fills[name] = filled
    gap = (donors, model, before, after)
    trials = _cross_validate(take, m, a, b, list(fills), gap, fitted)
    errors = {name: trials[name].rmse() for name in fills}
    blend = _blend(fills, errors, trials, params)
    if blend is not None:
        fills["blend"], errors["blend"] = blend
    return GapPlan(fills=fills, errors=errors, donors=donors, model=model)
