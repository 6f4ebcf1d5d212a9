"""The filter registry as the UI sees it, and a frame-by-frame streaming filter session.

Both wrap the filters package: :data:`mocapqa.filters.registry.FILTERS` and
:class:`mocapqa.filters.adaptive.AdaptiveFilter`. The stream takes its parameters the way
:func:`mocapqa.filters.apply.filter_keypoints` does: a registry preset (``default`` unless the
client names another) converted to the stream's length unit and frame rate, so streaming a take
gives the same output as filtering it in batch, up to a keypoint's first gap: over a gap the
batch filter, which sees the whole take, interpolates between the detections on either side
(:mod:`mocapqa.filters.gaps`), while the stream can only carry the filter's prediction. For
``px``, ``normalized`` and ``unknown`` units the body size is estimated from the first frame
(the batch filter uses the whole take).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.bounds import MAX_MAGNITUDE
from mocapqa.core.keypoints import LENGTH_UNITS
from mocapqa.errors import InputError
from mocapqa.filters.adaptive import AdaptiveFilter
from mocapqa.filters.apply import data_scale
from mocapqa.filters.registry import FILTERS, DataScale
from mocapqa.io.formats import check_fps

__all__ = ["StreamSession", "filter_catalog"]

METRIC_UNITS = ("m", "cm", "mm", "in")


def _plain(value: Any) -> Any:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, str | int | float | bool) or value is None:
        return value
    if isinstance(value, type):
        return value.__name__
    return str(value)


def filter_catalog() -> list[dict[str, Any]]:
    """Every registered filter: name, what it applies to, description, parameters (dotted
    names, defaults of the ``default`` preset at 30 fps in data units, units) and preset names."""
    catalog = []
    for entry in FILTERS.values():
        applies = ["keypoints", "rotations"] if entry.kind == "both" else [entry.kind]
        catalog.append(
            {
                "name": entry.name,
                "label": entry.name.replace("-", " "),
                "description": entry.summary,
                "parameters": [_plain(p) for p in entry.describe(DataScale())],
                "presets": sorted(entry.presets),
                "applies_to": applies,
            }
        )
    return catalog


class StreamSession:
    """A live keypoint stream filtered frame by frame with the streaming adaptive filter.

    Parameters
    ----------
    fps : float
        Frame rate of the stream, Hz.
    n_keypoints : int
        Keypoints per frame.
    length_unit : str
        Unit of the positions: "m", "cm", "mm", "in", "px", "normalized" or "unknown". Metric
        units convert exactly; the others take the body size from the first frame.
    preset : str
        A preset of the registry's ``adaptive`` filter ("default" or "note").

    Raises
    ------
    InputError
        On a bad frame rate (not finite, or not from :data:`~mocapqa.core.bounds.MIN_FPS` to
        :data:`~mocapqa.core.bounds.MAX_FPS`), keypoint count, unit or preset.
    """

    def __init__(
        self,
        fps: float,
        n_keypoints: int,
        length_unit: str = "unknown",
        preset: str = "default",
    ) -> None:
        check_fps(fps)
        if n_keypoints < 1:
            raise InputError(f"Expected n_keypoints ≥ 1, got {n_keypoints}")
        if length_unit not in LENGTH_UNITS:
            raise InputError(f"Expected a length unit in {LENGTH_UNITS}, got {length_unit!r}")
        if preset not in FILTERS["adaptive"].presets:
            raise InputError(
                f"Expected a preset in {sorted(FILTERS['adaptive'].presets)}, got {preset!r}"
            )
        self.n_keypoints = n_keypoints
        self.fps = fps
        self.length_unit = length_unit
        self.preset = preset
        self.frame = 0
        self._filter: AdaptiveFilter | None = None
        if length_unit in METRIC_UNITS:
            self._filter = self._make_filter(None)

    def _make_filter(self, first: FloatArray | None) -> AdaptiveFilter:
        scale = data_scale(self.length_unit, self.fps, first)
        params = FILTERS["adaptive"].preset(self.preset, scale)
        return AdaptiveFilter(params, self.n_keypoints, self.fps)

    def update(self, positions: Any, confidence: Any | None) -> dict[str, Any]:
        """Filter one frame.

        Parameters
        ----------
        positions : array-like, shape (K, 3)
            Positions in the stream's unit; ``None`` (or NaN) entries are missing.
        confidence : array-like, shape (K,), optional
            Confidence in [0, 1]; without it, 1 where a keypoint is present and 0 where missing.

        Returns
        -------
        dict
            ``frame``, ``positions`` (K, 3; ``None`` where the filter has no value yet) and
            ``weights`` (filter name → weight).
        """
        values, weights = self.filter(positions, confidence)
        index = self.frame - 1
        rounded = np.round(values, 5)
        return {
            "frame": index,
            "positions": [
                [float(v) if math.isfinite(v) else None for v in row] for row in rounded.tolist()
            ],
            "weights": _weights_json(weights),
        }

    def filter(self, positions: Any, confidence: Any | None) -> tuple[FloatArray, FloatArray]:
        """Filter one frame and return the arrays (unrounded).

        A frame is refused, before it changes the filter, when a coordinate is infinite or
        beyond ±:data:`~mocapqa.core.bounds.MAX_MAGNITUDE` (NaN is missing) or a confidence
        is not from 0 to 1 (NaN counts as 0).

        Returns
        -------
        filtered : ndarray, shape (K, 3)
            NaN where the keypoint has had no valid sample yet.
        weights : ndarray, shape (K, 3)
            Weights of (Kalman, One Euro, EMA).

        Raises
        ------
        InputError
            On a frame or confidence of another shape, or a value out of its bounds.
        """
        k = self.n_keypoints
        try:
            frame = np.asarray(positions, dtype=np.float64).reshape(k, 3)
            conf = (
                None if confidence is None else np.asarray(confidence, dtype=np.float64).reshape(k)
            )
        except (TypeError, ValueError, OverflowError) as e:
            raise InputError(f"Expected positions ({k}, 3) and confidence ({k},), got {e}") from e
        _check_frame(frame, conf)
        if conf is not None:
            conf = np.nan_to_num(conf, nan=0.0)
        if self._filter is None:
            self._filter = self._make_filter(frame[None])
        filtered, weights = self._filter.update(frame, conf)
        self.frame += 1
        return np.asarray(filtered, dtype=np.float64), np.asarray(weights, dtype=np.float64)


def _check_frame(frame: FloatArray, confidence: FloatArray | None) -> None:
    """Refuse a coordinate that is infinite or beyond ±MAX_MAGNITUDE, or a confidence not
    from 0 to 1 (NaN is missing in both), naming the first keypoint at fault."""
    over = np.abs(frame) > MAX_MAGNITUDE  # NaN compares False: missing
    if over.any():
        keypoint, axis = (int(i) for i in np.argwhere(over)[0])
        raise InputError(
            f"Expected coordinates within ±{int(MAX_MAGNITUDE):,} (the stream's length unit), "
            f"got {frame[keypoint, axis]:g} at keypoint {keypoint}"
        )
    if confidence is not None:
        bad = ~((confidence >= 0) & (confidence <= 1)) & ~np.isnan(confidence)
        if bad.any():
            keypoint = int(np.flatnonzero(bad)[0])
            raise InputError(
                f"Expected confidence from 0 to 1, got {confidence[keypoint]:g} at keypoint "
                f"{keypoint}"
            )


def _weights_json(weights: Any) -> dict[str, Any]:
    """Per filter: the weight per keypoint and their mean."""
    array = np.nan_to_num(np.asarray(weights, dtype=np.float64)).reshape(-1, 3)
    out: dict[str, Any] = {}
    for i, name in enumerate(("kalman", "one_euro", "ema")):
        out[name] = {
            "mean": round(float(array[:, i].mean()), 4),
            "per_keypoint": array[:, i].round(4).tolist(),
        }
    return out
