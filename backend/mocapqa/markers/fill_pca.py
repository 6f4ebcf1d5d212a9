"""PCA-intercorrelation fill of one marker gap (Gløersen & Federolf 2016).

Gløersen Ø, Federolf P (2016), "Predicting missing marker trajectories in human motion data using
marker intercorrelations", PLoS One 11(3): e0152616. Conventions as in
:mod:`mocapqa.markers.fill_methods`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.markers.fill_methods import anchor, frames_around, recorded_around

__all__ = ["PcaModel", "pca_fill", "pca_model"]


@dataclass(frozen=True, slots=True)
class PcaModel:
    """The normalised, weighted training matrix of a PCA fill (see :func:`pca_model`).

    Parameters
    ----------
    cols : ndarray of int, shape (K + 1,)
        The target marker followed by the model markers.
    train : ndarray of int, shape (N,)
        Training frames, increasing.
    z : ndarray, shape (N, 3 (K + 1))
        Normalised, weighted coordinates of the training frames.
    gram : ndarray, shape (3 (K + 1), 3 (K + 1))
        ``z.T @ z``.
    mean, sd, weight : ndarray, shape (3 (K + 1),)
        Per-coordinate mean and standard deviation (file units) and marker weight.
    centre : ndarray, shape (K,)
        Weights (summing to 1) of the model markers whose weighted mean, per frame, is taken
        out of every marker before the PCA; empty: none is.
    """

    cols: IntArray
    train: IntArray
    z: FloatArray
    gram: FloatArray
    mean: FloatArray
    sd: FloatArray
    weight: FloatArray
    centre: FloatArray


def pca_model(
    positions: FloatArray,
    visible: BoolArray,
    m: int,
    model: IntArray,
    *,
    exclude: tuple[int, int],
    weight_scale: float,
    max_train: int,
    centre: bool = False,
) -> PcaModel | None:
    """Training matrix of the PCA fill of marker ``m`` from the ``model`` markers.

    Parameters
    ----------
    positions, visible
        The take, as in :mod:`mocapqa.markers.fill_methods`.
    m : int
        Target marker.
    model : ndarray of int, shape (K,)
        The other markers of the model.
    exclude : tuple of int
        First and last frame left out of training (the gap).
    weight_scale : float
        Distance (file units) of the marker weights' fall-off.
    max_train : int
        Most training frames used (evenly spaced).
    centre : bool
        Take out of every marker, per frame, the mean of the model markers weighted as the
        markers are: the PCA then models where the target sits among its neighbours, not where
        the body is in the room.

    Returns
    -------
    PcaModel or None
        None without model markers or with fewer training frames than coordinates.
    """
    if model.size == 0:
        return None
    cols = np.concatenate(([m], model)).astype(np.intp)
    train_ok: BoolArray = np.asarray(visible[:, cols].all(axis=1))
    train_ok[exclude[0] : exclude[1] + 1] = False
    train = np.flatnonzero(train_ok)
    p = 3 * cols.size
    if train.size < max(p, 10):
        return None
    if train.size > max_train:
        train = train[np.linspace(0, train.size - 1, max_train).round().astype(np.intp)]
    xyz = positions[train[:, None], cols]
    dist = np.linalg.norm(xyz - xyz[:, :1], axis=2).mean(axis=0)
    near = np.exp(-((dist / weight_scale) ** 2))
    weights = near[1:] / max(float(near[1:].sum()), np.finfo(np.float64).tiny)
    centre_weight = weights if centre else np.zeros(0)
    xyz = _centred(xyz, centre_weight)
    x = xyz.reshape(train.size, p)
    mean = x.mean(axis=0)
    sd = x.std(axis=0)
    sd[sd == 0] = 1.0
    weight = np.repeat(near, 3)
    z = (x - mean) / sd * weight
    return PcaModel(cols, train, z, z.T @ z, mean, sd, weight, centre_weight)


def _centre_of(model_xyz: FloatArray, centre: FloatArray) -> FloatArray:
    """Per frame, the ``centre``-weighted mean of the model markers ``(N, K, 3)``: ``(N, 3)``
    (zeros when ``centre`` is empty)."""
    if centre.size == 0:
        return np.zeros((model_xyz.shape[0], 3))
    found: FloatArray = np.einsum("k,nkd->nd", centre, model_xyz)
    return found


def _centred(xyz: FloatArray, centre: FloatArray) -> FloatArray:
    """The target and model markers ``(N, K + 1, 3)`` less their frame's centre
    (:func:`_centre_of` of the model markers)."""
    shifted: FloatArray = xyz - _centre_of(xyz[:, 1:], centre)[:, None]
    return shifted


def pca_fill(
    positions: FloatArray,
    visible: BoolArray,
    m: int,
    a: int,
    b: int,
    model: IntArray,
    *,
    weight_scale: float,
    variance: float,
    max_train: int,
    window: int,
    smooth: bool = False,
    hidden: tuple[int, int] | None = None,
    fitted: PcaModel | None = None,
    before: bool = True,
    after: bool = True,
    centre: bool = False,
) -> FloatArray | None:
    """Fill a gap from the take's marker intercorrelations (Gløersen & Federolf 2016).

    The frames where the target and every model marker are visible (outside ``a..b`` and
    ``hidden``, at most ``max_train`` evenly spaced) are normalised per coordinate (mean and
    standard deviation) and weighted per marker by ``exp(-(d / weight_scale)²)``, ``d`` the
    marker's mean distance to the target, so that nearby markers dominate. A PCA of that matrix
    keeps the components that explain ``variance`` of it. In the gap, the target's coordinates
    are reconstructed from the visible model markers' weighted coordinates as their conditional
    mean under the probabilistic PCA model (the kept components plus isotropic noise at the
    discarded ones' mean variance): the paper's least-squares fit of the component scores,
    with weak components shrunk rather than trusted fully. Frames where other markers are
    missing too are handled by the choice of ``model`` (markers visible over the gap) and of the
    training frames (where all of them are visible). The result is corrected by its errors
    either side of the gap (:func:`~mocapqa.markers.fill_methods.anchor`).

    Parameters
    ----------
    positions, visible, m, a, b, before, after
        The take and the gap, as in :mod:`mocapqa.markers.fill_methods`.
    model : ndarray of int, shape (K,)
        The other markers of the model, visible over ``a..b``.
    weight_scale : float
        Distance (file units) of the marker weights' fall-off.
    variance : float
        Share of the weighted, normalised variance the kept components explain, in (0, 1].
    max_train : int
        Most training frames used.
    window : int
        Frames either side of the gap whose errors correct the prediction.
    smooth : bool
        Correct by a cubic spline of the errors rather than the boundary errors' linear blend.
    centre : bool
        Of a matrix built here: positions relative to the neighbours (:func:`pca_model`).
    hidden : tuple of int, optional
        Another stretch of the target (first, last frame) to leave out of training.
    fitted : PcaModel, optional
        A training matrix of the same target and model built by :func:`pca_model` (its
        training frames inside ``a..b`` and ``hidden`` are taken out); built here when omitted.

    Returns
    -------
    ndarray, shape (b - a + 1, 3), or None
        None without model markers, with fewer training frames than coordinates, or when a
        model marker is missing in the gap.
    """
    times = _usable_times(visible, a, b, model, window, before, after)
    if times is None:
        return None
    if fitted is None:
        fitted = pca_model(
            positions, visible, m, model,
            exclude=hidden or (a, b), weight_scale=weight_scale, max_train=max_train,
            centre=centre,
        )  # fmt: skip
        if fitted is None:
            return None
    seen = positions[times[:, None], fitted.cols[1:]]
    gram = _gram_without(fitted, {(a, b), hidden or (a, b)})
    predicted = _predicted(fitted, gram, seen, variance)
    recorded = recorded_around(positions, visible, m, times, a, b)
    return anchor(predicted, times, recorded, a, b, smooth=smooth)


def _predicted(fitted: PcaModel, gram: FloatArray, seen: FloatArray, variance: float) -> FloatArray:
    """The target ``(T, 3)`` from the model markers ``seen`` ``(T, K, 3)`` (file units): their
    centre taken out when the model says so, the conditional mean, the centre put back."""
    middle = _centre_of(seen, fitted.centre)
    y = (seen - middle[:, None]).reshape(seen.shape[0], -1)
    predicted: FloatArray = middle + _conditional_target(fitted, gram, y, variance)
    return predicted


def _usable_times(
    visible: BoolArray,
    a: int,
    b: int,
    model: IntArray,
    window: int,
    before: bool,
    after: bool,
) -> IntArray | None:
    """The frames around and in the gap where every model marker is visible; None without
    model markers or when one is missing in the gap."""
    times, _, _ = frames_around(visible.shape[0], a, b, window, before, after)
    if model.size == 0:
        return None
    times = times[visible[times[:, None], model].all(axis=1)]
    if np.count_nonzero((times >= a) & (times <= b)) < b - a + 1:
        return None
    usable: IntArray = times
    return usable


def _gram_without(fitted: PcaModel, stretches: set[tuple[int, int]]) -> FloatArray:
    """``fitted.gram`` less the training frames inside each (first, last) stretch."""
    gram = fitted.gram
    for lo, hi in stretches:
        rows = fitted.z[
            np.searchsorted(fitted.train, lo) : np.searchsorted(fitted.train, hi, "right")
        ]
        if rows.size:
            gram = gram - rows.T @ rows
    return gram


def _conditional_target(
    fitted: PcaModel, gram: FloatArray, y: FloatArray, variance: float
) -> FloatArray:
    """The target's coordinates ``(T, 3)`` given the model markers' ``y`` ``(T, 3 K)``.

    The conditional mean under the probabilistic PCA model (the components that explain
    ``variance`` of ``gram``, plus isotropic noise at the discarded components' mean variance):
    a least-squares fit of the scores that shrinks the weak components instead of trusting
    them fully.
    """
    p = fitted.cols.size * 3
    eigval, eigvec = np.linalg.eigh(gram)
    eigval, eigvec = np.maximum(eigval[::-1], 0.0), eigvec[:, ::-1]
    share = np.cumsum(eigval) / max(float(np.sum(eigval)), np.finfo(np.float64).tiny)
    k = min(int(np.searchsorted(share, variance)) + 1, p - 3)
    v = eigvec[:, :k]
    mean, sd, weight = fitted.mean, fitted.sd, fitted.weight
    zo = (y - mean[3:]) / sd[3:] * weight[3:]
    noise = max(float(eigval[k:].mean()) if k < p else 0.0, 1e-9 * float(eigval[0]))
    cov = (v * eigval[:k]) @ v.T + noise * np.eye(p)
    zt = cov[:3, 3:] @ np.linalg.solve(cov[3:, 3:], zo.T)
    predicted: FloatArray = zt.T / weight[:3] * sd[:3] + mean[:3]
    return predicted
