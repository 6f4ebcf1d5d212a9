"""The one table of filters behind the CLI choices, the API enum and the UI dropdown.

Conventions
-----------
Each :class:`FilterEntry` names a method, says what it filters (``"keypoints"``,
``"rotations"`` or ``"both"``), gives its parameter dataclass and its presets. Presets are
functions of a :class:`DataScale` (the data's units per metre and per normalised unit, and its
frame rate) because thresholds and noise levels must follow the data's units: a preset is
stated once in physical units and converted, never assumed.

Presets:

* ``note`` — the adaptive multi-filter note's numbers exactly (Kalman q = 1e−2, r = 3e−5;
  One Euro 1.0 Hz, β = 0.007, 1.0 Hz; EMA α = 0.3 at the note's 30 fps, i.e. τ = 0.0934 s;
  window 5 frames at 30 fps = 0.167 s; speeds 0.1 and 1.0 unit/s), read in normalised
  coordinates and converted with the stated assumption that **one normalised unit is 2.0 m**
  (the image height framing a standing adult) for metric data, or the data's own body extent
  (÷ 0.85) for pixel and unknown units.
* ``default`` — values tuned on the Bandai training takes by ``mocapqa bench filters``, stated
  in metres and seconds and converted to the data's units.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

from mocapqa.filters.adaptive import AdaptiveParams
from mocapqa.filters.butterworth import ButterworthParams
from mocapqa.filters.ema import EmaParams, time_constant_from_alpha
from mocapqa.filters.kalman import KalmanParams
from mocapqa.filters.one_euro import OneEuroParams
from mocapqa.filters.quat_one_euro import QuatOneEuroParams
from mocapqa.filters.quat_pd import QuatPDParams
from mocapqa.filters.ranges import range_of

__all__ = [
    "FILTERS",
    "NOTE_FPS",
    "NOTE_METRES_PER_UNIT",
    "DataScale",
    "FilterEntry",
    "ParamInfo",
]

NOTE_FPS = 30.0
"""Frame rate the note's numbers were chosen at."""
NOTE_METRES_PER_UNIT = 2.0
"""Stated assumption: one normalised image unit of the note's data is 2.0 m."""


@dataclass(frozen=True, slots=True)
class DataScale:
    """How the data's length unit relates to physical and normalised units.

    Parameters
    ----------
    units_per_metre : float
        Data units in one metre (100 for cm; for pixels an estimate from the body extent).
    units_per_normalised : float
        Data units in one normalised image unit (1 for normalised data).
    fps : float
        Frames per second of the data.
    """

    units_per_metre: float = 1.0
    units_per_normalised: float = NOTE_METRES_PER_UNIT
    fps: float = 30.0


@dataclass(frozen=True, slots=True)
class ParamInfo:
    """One parameter for a UI form: dotted ``name``, ``default``, ``unit``, ``type`` and the
    declared range's bounds (:mod:`mocapqa.filters.ranges`; None where none is declared; a
    bound ``*_excluded`` is not itself allowed), so a form can refuse a value before it is
    sent."""

    name: str
    default: Any
    unit: str
    type: str
    minimum: float | None = None
    maximum: float | None = None
    minimum_excluded: bool = False
    maximum_excluded: bool = False


_UNITS = {
    "process_noise": "unit²/s⁴",
    "measurement_noise": "unit²",
    "beta": "Hz per unit/s",
    "slow_speed": "unit/s",
    "fast_speed": "unit/s",
    "gate_sigma": "σ",
}


def _unit(entry: str, name: str) -> str:
    if name.endswith("_hz"):
        return "Hz"
    if name.endswith("_s"):
        return "s"
    if entry.startswith("quat") and name == "beta":
        return "Hz per rad/s"
    return _UNITS.get(name, "")


def _flatten(entry: str, params: Any, prefix: str = "") -> list[ParamInfo]:
    out: list[ParamInfo] = []
    for f in dataclasses.fields(params):
        value = getattr(params, f.name)
        if dataclasses.is_dataclass(value):
            out += _flatten(entry, value, f"{prefix}{f.name}.")
        else:
            bounds = range_of(params, f.name)
            out.append(
                ParamInfo(
                    prefix + f.name,
                    value,
                    _unit(entry, f.name),
                    type(value).__name__,
                    None if bounds is None else bounds.low,
                    None if bounds is None else bounds.high,
                    bounds is not None and bounds.low_open,
                    bounds is not None and bounds.high_open,
                )
            )
    return out


@dataclass(frozen=True, slots=True)
class FilterEntry:
    """A filter method: its name, kind, parameter type and presets.

    Parameters
    ----------
    name : str
        CLI/API name, e.g. ``"one-euro"``.
    kind : {"keypoints", "rotations", "both"}
        What the method filters.
    params : type
        The parameter dataclass.
    presets : mapping of str to callable
        Preset name → function of :class:`DataScale` returning a parameter instance.
    summary : str
        One line for help texts.
    """

    name: str
    kind: Literal["keypoints", "rotations", "both"]
    params: type
    presets: Mapping[str, Callable[[DataScale], Any]]
    summary: str

    def preset(self, name: str, scale: DataScale) -> Any:
        """Parameters of preset ``name`` for data of ``scale``."""
        from mocapqa.errors import InputError

        if name not in self.presets:
            raise InputError(
                f"Expected a preset of {self.name!r} in {sorted(self.presets)}, got {name!r}"
            )
        return self.presets[name](scale)

    def describe(self, scale: DataScale | None = None) -> list[ParamInfo]:
        """Parameter names, defaults (the ``default`` preset at ``scale``) and units."""
        return _flatten(self.name, self.preset("default", scale or DataScale()))


# Tuned on the Bandai training takes (``mocapqa bench filters``), metres and seconds.
DEFAULT_PROCESS_NOISE_M2_S4 = 300.0
DEFAULT_MEASUREMENT_NOISE_M2 = 0.0075**2
DEFAULT_GATE_SIGMA = 0.0
DEFAULT_BRIDGE_DECAY_S = 0.1


def _kalman_default(s: DataScale) -> KalmanParams:
    u2 = s.units_per_metre**2
    return KalmanParams(
        process_noise=DEFAULT_PROCESS_NOISE_M2_S4 * u2,
        measurement_noise=DEFAULT_MEASUREMENT_NOISE_M2 * u2,
        confidence_weighted=True,
        gate_sigma=DEFAULT_GATE_SIGMA,
        bridge_decay_s=DEFAULT_BRIDGE_DECAY_S,
    )


def _kalman_note(s: DataScale) -> KalmanParams:
    u2 = s.units_per_normalised**2
    return KalmanParams(process_noise=1e-2 * u2, measurement_noise=3e-5 * u2)


def _one_euro_note(s: DataScale) -> OneEuroParams:
    return OneEuroParams(min_cutoff_hz=1.0, beta=0.007 / s.units_per_normalised, d_cutoff_hz=1.0)


def _one_euro_default(s: DataScale) -> OneEuroParams:
    return OneEuroParams(min_cutoff_hz=1.0, beta=8.0 / s.units_per_metre, d_cutoff_hz=1.0)


def _ema_note(s: DataScale) -> EmaParams:
    return EmaParams(time_constant_s=time_constant_from_alpha(0.3, NOTE_FPS))


def _ema_default(s: DataScale) -> EmaParams:
    return EmaParams(time_constant_s=0.03)


def _adaptive_note(s: DataScale) -> AdaptiveParams:
    u = s.units_per_normalised
    return AdaptiveParams(
        kalman=_kalman_note(s),
        one_euro=_one_euro_note(s),
        ema=_ema_note(s),
        weighting="rules",
        window_s=5 / NOTE_FPS,
        slow_speed=0.1 * u,
        fast_speed=1.0 * u,
    )


def _adaptive_default(s: DataScale) -> AdaptiveParams:
    return AdaptiveParams(
        kalman=dataclasses.replace(_kalman_default(s), bridge_decay_s=0.03),
        one_euro=_one_euro_default(s),
        ema=EmaParams(time_constant_s=0.1),
        weighting="innovation",
        window_s=0.3,
        slow_speed=0.1 * s.units_per_normalised,
        fast_speed=1.0 * s.units_per_normalised,
        innovation_power=3.0,
        share_bridges=True,
        body_prior=True,
    )


# The one table of filter methods, by CLI/API name.
FILTERS: dict[str, FilterEntry] = {
    e.name: e
    for e in (
        FilterEntry(
            "adaptive",
            "keypoints",
            AdaptiveParams,
            {"default": _adaptive_default, "note": _adaptive_note},
            "Blend of Kalman, One Euro and EMA with per-keypoint weights",
        ),
        FilterEntry(
            "kalman",
            "keypoints",
            KalmanParams,
            {"default": _kalman_default, "note": _kalman_note},
            "Constant-velocity Kalman, confidence-weighted with outlier gating",
        ),
        FilterEntry(
            "one-euro",
            "keypoints",
            OneEuroParams,
            {"default": _one_euro_default, "note": _one_euro_note},
            "One Euro filter (Casiez et al. 2012)",
        ),
        FilterEntry(
            "ema",
            "keypoints",
            EmaParams,
            {"default": _ema_default, "note": _ema_note},
            "Exponential moving average with a time constant",
        ),
        FilterEntry(
            "butterworth",
            "both",
            ButterworthParams,
            {"default": lambda s: ButterworthParams()},
            "Zero-phase Butterworth low-pass (offline reference)",
        ),
        FilterEntry(
            "quat-pd",
            "rotations",
            QuatPDParams,
            {"default": lambda s: QuatPDParams()},
            "Quaternion PD kinematics filter (QuaMo), exact S³ integration",
        ),
        FilterEntry(
            "quat-one-euro",
            "rotations",
            QuatOneEuroParams,
            {"default": lambda s: QuatOneEuroParams()},
            "One Euro filter on the quaternion sphere",
        ),
        FilterEntry(
            "euler-pd",
            "rotations",
            QuatPDParams,
            {"default": lambda s: QuatPDParams()},
            "PD on unwrapped Euler angles (ablation baseline only)",
        ),
    )
}
