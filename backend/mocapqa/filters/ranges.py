"""The range of every filter parameter, declared with the parameter and checked when it is set.

Conventions
-----------
A parameter dataclass declares each number field with :func:`bounded`, naming one of the
ranges below; its ``__post_init__`` calls :func:`check_ranges` first. Presets, the CLI's
``--param NAME=VALUE``, the API's ``filter_params`` and the stream all build their parameters
through these dataclasses, so the one check covers them all: a value that is not a real number,
not finite (``inf``, ``nan``, ``1e400``) or outside its range is refused with an
:class:`~mocapqa.errors.InputError` naming the parameter, the range and its unit.

The ranges keep every filter finite and its memory bounded: a window of 10⁹ s would allocate
terabytes, an infinite cut-off or noise turns the output into NaN, an innovation power of 100
overflows the blend's weights, ``gate_sigma`` of 10³⁰⁰ overflows its square.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, TypeVar

from mocapqa.errors import InputError

__all__ = [
    "BELOW_ONE",
    "DURATION",
    "DURATION_OR_OFF",
    "FREQUENCY",
    "NOISE",
    "NON_NEGATIVE",
    "ORDER",
    "POSITIVE",
    "POWER",
    "SIGMA",
    "UNIT_INTERVAL",
    "Range",
    "bounded",
    "check_ranges",
    "range_of",
]

T = TypeVar("T")


@dataclass(frozen=True, slots=True)
class Range:
    """Allowed values of a number parameter: finite, from ``low`` to ``high``.

    Parameters
    ----------
    low, high : float
        The bounds.
    unit : str
        Unit named in messages ("s", "Hz"; empty for unit-free or data-unit values).
    low_open, high_open : bool
        Whether the bound itself is excluded.
    """

    low: float
    high: float
    unit: str = ""
    low_open: bool = False
    high_open: bool = False

    def __contains__(self, value: object) -> bool:
        if isinstance(value, bool) or not isinstance(value, int | float):
            return False
        try:  # an int beyond a float's range (10**309) overflows here: not in any range
            if not math.isfinite(value):
                return False
        except OverflowError:
            return False
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below

    def describe(self) -> str:
        """The range as text: ``"0.0001 to 60 s"``, ``"> 0 and at most 1e+20"``, ``"0 to 1"``."""
        unit = f" {self.unit}" if self.unit else ""
        if self.low_open or self.high_open:
            low = f"> {self.low:g}" if self.low_open else f">= {self.low:g}"
            high = f"< {self.high:g}" if self.high_open else f"at most {self.high:g}"
            return f"{low} and {high}{unit}"
        return f"{self.low:g} to {self.high:g}{unit}"


DURATION = Range(1e-4, 60.0, "s")
"""Windows and time constants, seconds: 0.1 ms (100 frames at the 100,000 fps a take may have)
to a minute (far beyond any motion filter's memory)."""
DURATION_OR_OFF = Range(0.0, 60.0, "s")
"""Durations where 0 switches the feature off (``bridge_decay_s``, ``lead_s``), seconds."""
FREQUENCY = Range(1e-3, 1e4, "Hz")
"""Cut-off and natural frequencies, Hz."""
NOISE = Range(1e-24, 1e24)
"""Kalman noise variances, in the data's units (unit², unit²/s⁴): wide enough for every preset
at any length unit, narrow enough that the blend's innovation weights stay finite."""
POSITIVE = Range(0.0, 1e20, low_open=True)
"""Positive numbers with no natural scale (a damping ratio)."""
NON_NEGATIVE = Range(0.0, 1e20)
"""Slopes and speeds in the data's units (One Euro ``beta``, speed thresholds)."""
POWER = Range(0.0, 10.0, low_open=True)
"""Exponent of the innovation weights: beyond 10 they overflow on data in small units."""
ORDER = Range(1, 8)
"""Butterworth filter order."""
SIGMA = Range(0.0, 1000.0, "σ")
"""Gates in predicted standard deviations; 0 switches gating off."""
UNIT_INTERVAL = Range(0.0, 1.0)
"""Shares, scores and confidence thresholds."""
BELOW_ONE = Range(0.0, 1.0, high_open=True)
"""Confidence floors below which a sample is missing (1 would drop every sample)."""


def bounded(default: T, allowed: Range) -> T:
    """A dataclass field with ``default`` whose values must lie in ``allowed``.

    Typed as the default so that type checkers read it as one; the dataclass receives the
    :func:`dataclasses.field` carrying the range.
    """
    return dataclasses.field(default=default, metadata={"range": allowed})


def range_of(params: Any, name: str) -> Range | None:
    """The declared range of field ``name`` of the parameter dataclass ``params``, if any."""
    for f in dataclasses.fields(params):
        if f.name == name:
            found = f.metadata.get("range")
            return found if isinstance(found, Range) else None
    return None


def _shown(value: object) -> str:
    """A refused value for a message: a huge integer by its size, not its 400 digits."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**16:
        return f"an integer of {len(str(abs(value)))} digits"
    return repr(value)


def check_ranges(params: Any) -> None:
    """Refuse a parameter dataclass with a number outside its declared range.

    Parameters
    ----------
    params : dataclass instance
        Fields declared with :func:`bounded` are checked; others are left to the class.

    Raises
    ------
    InputError
        Naming the field, its range and the value, e.g. ``Expected `window_s` 0.0001 to 60 s,
        got inf``.
    """
    for f in dataclasses.fields(params):
        allowed = f.metadata.get("range")
        if not isinstance(allowed, Range):
            continue
        value = getattr(params, f.name)
        if value not in allowed:
            raise InputError(f"Expected `{f.name}` {allowed.describe()}, got {_shown(value)}")
