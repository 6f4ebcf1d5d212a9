"""Apply a registered filter to a keypoint sequence or a BVH motion.

Conventions
-----------
The data's scale (:class:`~mocapqa.filters.registry.DataScale`) comes from the sequence's
recorded ``length_unit``: metric units convert exactly; for ``normalized`` data one normalised
unit is the unit itself; for ``px`` and ``unknown`` the scale is estimated from the body extent
(median per-frame extent of the keypoints along their widest axis, read as 1.7 m).

Gaps are bridged offline and never extrapolated (:mod:`mocapqa.filters.gaps`): a keypoint's
frames without a detection are filled before filtering (interpolated between the detections
around them, held before the first and after the last), so a filter never coasts through a
gap on its own prediction (a Kalman bridge placed cam01's OpenPose LEar 100 px beyond its
detections); after filtering, those frames take the straight line between the filtered
samples on either side of the gap, or hold the nearest one at the take's ends. Every bridged
sample (also a filter's prediction over a low-confidence or rejected sample) is kept within
the range of its keypoint's detections on each axis, so pixel data stay inside the image.
Causal filters cannot produce a value before a keypoint's first valid sample; those frames
take the first output value and are marked bridged. A keypoint with no valid sample at all
stays NaN and is marked bridged (a gap), rather than inventing values.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError, OptionError
from mocapqa.filters.adaptive import WEIGHT_NAMES, adaptive_filter
from mocapqa.filters.butterworth import butterworth_filter, butterworth_quats
from mocapqa.filters.ema import ema_filter
from mocapqa.filters.euler_pd import euler_pd_filter, vector_pd_filter
from mocapqa.filters.gaps import clamp_to_detections, fill_gaps
from mocapqa.filters.kalman import kalman_filter
from mocapqa.filters.one_euro import OneEuroParams, one_euro_filter
from mocapqa.filters.quat_one_euro import quat_one_euro_filter
from mocapqa.filters.quat_pd import quat_pd_filter
from mocapqa.filters.registry import FILTERS, NOTE_METRES_PER_UNIT, DataScale
from mocapqa.kinematics.bindpose import leading_bind_pose

__all__ = [
    "ASSUMED_BODY_HEIGHT_M",
    "KeypointFilterResult",
    "apply_overrides",
    "data_scale",
    "filter_keypoints",
    "filter_motion",
    "resolve_params",
]

ASSUMED_BODY_HEIGHT_M = 1.7
"""Body height assumed when a scale must be estimated from pixel or unknown-unit data."""

_METRES = {"m": 1.0, "cm": 100.0, "mm": 1000.0, "in": 1.0 / 0.0254}


def data_scale(length_unit: str, fps: float, positions: FloatArray | None = None) -> DataScale:
    """The :class:`DataScale` of data in ``length_unit`` at ``fps``.

    Parameters
    ----------
    length_unit : str
        "m", "cm", "mm", "in", "px", "normalized" or "unknown".
    fps : float
        Frames per second.
    positions : ndarray, shape (F, K, 3), optional
        Needed for "px" and "unknown" units (scale from the body extent).

    Raises
    ------
    InputError
        If the scale must be estimated and no usable positions are given.
    """
    if length_unit in _METRES:
        upm = _METRES[length_unit]
        return DataScale(upm, NOTE_METRES_PER_UNIT * upm, fps)
    if length_unit == "normalized":
        extent = _extent(positions) if positions is not None else 0.85
        return DataScale(extent / ASSUMED_BODY_HEIGHT_M, 1.0, fps)
    extent = _extent(positions) if positions is not None else float("nan")
    if not np.isfinite(extent) or extent <= 0:
        raise InputError(
            f"Expected metric units or keypoints to estimate the body size from, got "
            f"length_unit {length_unit!r} without usable positions"
        )
    upm = extent / ASSUMED_BODY_HEIGHT_M
    return DataScale(upm, extent / 0.85, fps)


def _extent(positions: FloatArray | None) -> float:
    if positions is None or positions.size == 0 or np.isnan(positions).all():
        return float("nan")
    span = np.nanmax(positions, axis=1) - np.nanmin(positions, axis=1)
    return float(np.nanmedian(np.nanmax(span, axis=-1)))


def _coerce(text: str, current: Any, name: str) -> Any:
    if isinstance(current, bool):
        if text.lower() in ("1", "true", "yes", "on"):
            return True
        if text.lower() in ("0", "false", "no", "off"):
            return False
        raise InputError(f"Expected true/false for parameter {name!r}, got {text!r}")
    try:
        if isinstance(current, int):
            return int(text)
        if isinstance(current, float):
            return float(text)
    except ValueError as e:
        raise InputError(f"Expected a number for parameter {name!r}, got {text!r}") from e
    return text


def apply_overrides(params: Any, overrides: dict[str, Any]) -> Any:
    """A copy of the dataclass ``params`` with dotted-name ``overrides`` applied.

    Values may be strings (from the command line); they are converted to the field's type.
    Each parameter dataclass checks its values when made (the ranges of
    :mod:`mocapqa.filters.ranges`).

    Raises
    ------
    OptionError
        On an unknown name, an unconvertible value or one outside the parameter's range; its
        ``field`` is the dotted name (``kalman.process_noise``).
    """
    for key, value in overrides.items():
        try:
            params = _override(params, key, value)
        except OptionError:
            raise
        except InputError as e:
            raise OptionError(key, str(e)) from e
    return params


def _override(params: Any, key: str, value: Any) -> Any:
    head, _, rest = key.partition(".")
    names = [f.name for f in dataclasses.fields(params)]
    if head not in names:
        raise InputError(f"Expected a parameter in {names}, got {key!r}")
    current = getattr(params, head)
    if rest:
        if not dataclasses.is_dataclass(current):
            raise InputError(f"Expected a parameter in {names}, got {key!r}")
        new = _override(current, rest, value)
    else:
        new = _coerce(value, current, key) if isinstance(value, str) else value
    return dataclasses.replace(params, **{head: new})


def resolve_params(
    method: str, preset: str, scale: DataScale, params: dict[str, Any] | None
) -> Any:
    """The parameter dataclass of ``method``: ``preset`` at ``scale`` plus ``params`` overrides."""
    if method not in FILTERS:
        raise InputError(f"Expected a filter method in {sorted(FILTERS)}, got {method!r}")
    base = FILTERS[method].preset(preset, scale)
    return apply_overrides(base, params or {})


@dataclass(frozen=True, slots=True)
class KeypointFilterResult:
    """A filtered keypoint sequence and what the filter did.

    Parameters
    ----------
    sequence : KeypointSequence
        Filtered keypoints (confidence unchanged).
    weights : ndarray, shape (F, K, 3) or None
        Blend weights of the adaptive filter, in the order of ``weight_names``.
    weight_names : tuple of str
        Names of the blended filters (empty without weights).
    bridged : ndarray of bool, shape (F, K)
        True where the output is a prediction or interpolation, not a filtered sample.
    method : str
        Method name.
    params : object
        The parameter dataclass used.
    """

    sequence: KeypointSequence
    weights: FloatArray | None
    weight_names: tuple[str, ...]
    bridged: BoolArray
    method: str
    params: Any

    def to_json(self, max_points: int | None = None) -> dict[str, Any]:
        """A JSON-ready summary: method, params, bridged counts and the weight timeline.

        Parameters
        ----------
        max_points : int, optional
            Keep at most this many frames of the timeline (evenly spaced).
        """
        n = self.sequence.n_frames
        frames = np.arange(n)
        if max_points is not None and n > max_points > 0:
            frames = np.unique(np.linspace(0, n - 1, max_points).round().astype(int))
        out: dict[str, Any] = {
            "method": self.method,
            "params": dataclasses.asdict(self.params),
            "fps": self.sequence.fps,
            "length_unit": self.sequence.length_unit,
            "keypoints": list(self.sequence.names),
            "bridged_fraction": float(self.bridged.mean()) if self.bridged.size else 0.0,
            "bridged_per_keypoint": self.bridged.sum(axis=0).tolist(),
            "weight_names": list(self.weight_names),
            "timeline_frames": frames.tolist(),
        }
        if self.weights is not None:
            w = self.weights[frames]
            out["weights_mean"] = np.round(w.mean(axis=1), 4).tolist()
            out["weights"] = np.round(w, 4).tolist()
            out["weights_overall_mean"] = np.round(self.weights.mean(axis=(0, 1)), 4).tolist()
        return out


def _fill_leading(values: FloatArray, bridged: BoolArray) -> tuple[FloatArray, BoolArray]:
    """Give frames before a channel's first output that first output; mark them bridged."""
    nan = np.isnan(values)
    if not nan.any():
        return values, bridged
    n = values.shape[0]
    first = np.argmax(~nan, axis=0)
    idx = np.maximum(np.arange(n).reshape((n,) + (1,) * (values.ndim - 1)), first)
    filled = np.take_along_axis(values, idx, axis=0)
    return filled, bridged | nan


def _any3(flags: BoolArray) -> BoolArray:
    return np.asarray(flags.any(axis=2))


def filter_keypoints(
    seq: KeypointSequence,
    method: str = "adaptive",
    preset: str = "default",
    params: dict[str, Any] | None = None,
) -> KeypointFilterResult:
    """Filter a keypoint sequence with a registered method.

    Parameters
    ----------
    seq : KeypointSequence
        Input keypoints; NaN where missing.
    method : str
        A name in :data:`~mocapqa.filters.registry.FILTERS` of kind "keypoints" or "both".
    preset : {"default", "note"}
        Parameter preset, converted to the data's units and frame rate.
    params : dict, optional
        Overrides by dotted name, e.g. ``{"kalman.gate_sigma": 3.0}``.

    Returns
    -------
    KeypointFilterResult

    Raises
    ------
    InputError
        On an unknown method, preset or parameter, or a rotation-only method.
    """
    if method in FILTERS and FILTERS[method].kind == "rotations":
        raise InputError(f"Expected a keypoint filter method, got rotation method {method!r}")
    scale = data_scale(seq.length_unit, seq.fps, seq.positions)
    p = resolve_params(method, preset, scale, params)
    missing, fps = seq.missing, seq.fps
    # The filters run over the gaps filled from the detections on either side (weighed by
    # their confidence), not over a coasting prediction.
    pos = fill_gaps(seq.positions, missing)
    conf = fill_gaps(seq.confidence, missing)
    conf3 = np.repeat(conf[:, :, None], 3, axis=2)
    weights: FloatArray | None = None
    names: tuple[str, ...] = ()
    if method == "adaptive":
        res = adaptive_filter(pos, fps, p, conf)
        values, bridged, weights, names = res.values, res.bridged, res.weights, WEIGHT_NAMES
    elif method == "kalman":
        kres = kalman_filter(pos, fps, p, conf3)
        values, bridged = kres.values, _any3(kres.bridged)
    elif method == "one-euro":
        values, b = one_euro_filter(pos, fps, p, conf3)
        bridged = _any3(b)
    elif method == "ema":
        values, b = ema_filter(pos, fps, p, conf3)
        bridged = _any3(b)
    else:
        values, b = butterworth_filter(pos, fps, p)
        bridged = _any3(b)
    values, b3 = _fill_leading(values, np.repeat(bridged[:, :, None], 3, axis=2))
    detected = ~missing.all(axis=0)
    bridged = _any3(b3) | (missing & detected)
    values = fill_gaps(values, missing)
    values = clamp_to_detections(values, seq.positions, bridged)
    out = dataclasses.replace(
        seq, positions=values, confidence=np.where(np.isnan(values).any(-1), 0.0, seq.confidence)
    )
    return KeypointFilterResult(out, weights, names, bridged, method, p)


def filter_motion(
    motion: Motion, method: str = "quat-pd", params: dict[str, Any] | None = None
) -> Motion:
    """Filter every joint's local rotation of a BVH motion, and its root translation.

    Parameters
    ----------
    motion : Motion
        The take.
    method : str
        "quat-pd", "quat-one-euro", "euler-pd" or "butterworth".
    params : dict, optional
        Overrides of the method's default parameters.

    Returns
    -------
    Motion
        Same skeleton and frame rate; filtered rotations and position channels.

    Raises
    ------
    InputError
        On a keypoint-only method or bad parameters.
    """
    if method not in FILTERS or FILTERS[method].kind == "keypoints":
        allowed = sorted(n for n, e in FILTERS.items() if e.kind != "keypoints")
        raise InputError(f"Expected a rotation filter method in {allowed}, got {method!r}")
    scale = DataScale(1.0, NOTE_METRES_PER_UNIT, motion.fps)
    p = resolve_params(method, "default", scale, params)
    fps = motion.fps
    # A bind-pose first frame is kept as it is and the filter starts on the motion.
    skip = leading_bind_pose(motion.quats)
    raw_quats, raw_translations = motion.quats[skip:], motion.translations[skip:]
    if method == "quat-pd":
        quats = quat_pd_filter(raw_quats, fps, p)
        translations = vector_pd_filter(raw_translations, fps, p)
    elif method == "euler-pd":
        orders = [motion.skeleton.rotation_order(j) for j in range(motion.skeleton.n_joints)]
        quats = euler_pd_filter(raw_quats, orders, fps, p)
        translations = vector_pd_filter(raw_translations, fps, p)
    elif method == "quat-one-euro":
        quats = quat_one_euro_filter(raw_quats, fps, p)
        pos_params = OneEuroParams(
            min_cutoff_hz=p.min_cutoff_hz, beta=0.0, d_cutoff_hz=p.d_cutoff_hz
        )
        translations, _ = one_euro_filter(raw_translations, fps, pos_params)
    else:
        quats = butterworth_quats(raw_quats, fps, p)
        translations, _ = butterworth_filter(raw_translations, fps, p)
    quats = np.concatenate([motion.quats[:skip], quats])
    translations = np.concatenate([motion.translations[:skip], translations])
    return dataclasses.replace(motion, quats=quats, translations=translations)
