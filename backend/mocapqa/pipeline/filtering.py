"""The filter registry as the UI sees it, and a frame-by-frame streaming filter session.

Both wrap the filters package: :data:`mocapqa.filters.registry.FILTERS` and
:class:`mocapqa.filters.adaptive.AdaptiveFilter` (default parameters, in data units).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from mocapqa.errors import InputError
from mocapqa.filters.adaptive import AdaptiveFilter, AdaptiveParams
from mocapqa.filters.registry import FILTERS, DataScale

__all__ = ["StreamSession", "filter_catalog"]


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
    """

    def __init__(self, fps: float, n_keypoints: int) -> None:
        if not (math.isfinite(fps) and fps > 0) or n_keypoints < 1:
            raise InputError(f"Expected fps > 0 and n_keypoints ≥ 1, got {fps}, {n_keypoints}")
        self.n_keypoints = n_keypoints
        self.frame = 0
        self._filter = AdaptiveFilter(AdaptiveParams(), n_keypoints, fps)

    def update(self, positions: Any, confidence: Any | None) -> dict[str, Any]:
        """Filter one frame.

        Parameters
        ----------
        positions : array-like, shape (K, 3)
        confidence : array-like, shape (K,), optional

        Returns
        -------
        dict
            ``frame``, ``positions`` (K, 3) and ``weights`` (filter name → weight).
        """
        try:
            frame = np.asarray(positions, dtype=np.float64).reshape(self.n_keypoints, 3)
            conf = (
                np.ones(self.n_keypoints)
                if confidence is None
                else np.asarray(confidence, dtype=np.float64).reshape(self.n_keypoints)
            )
        except (TypeError, ValueError) as e:
            raise InputError(
                f"Expected positions ({self.n_keypoints}, 3) and confidence "
                f"({self.n_keypoints},), got {e}"
            ) from e
        filtered, weights = self._filter.update(frame, conf)
        index = self.frame
        self.frame += 1
        values = np.asarray(filtered, dtype=np.float64).reshape(self.n_keypoints, 3)
        return {
            "frame": index,
            "positions": np.where(np.isfinite(values), np.round(values, 5), 0.0).tolist(),
            "weights": _weights_json(weights),
        }


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
