"""How large a rig's natural roll steps are, and the smallest level that can be told from them.

A small twist offset (5–20°) is a level shift whose onset is a counter-rotated step of the
parent's roll. The robust detector also reads such steps on *clean* takes: a fast natural roll
that the child partly counter-rotates (the 30 fps Bandai upper arms step by 3–17° per frame)
makes events whose jumps look like the onset of a small shift. An offset smaller than those
natural jumps cannot be told from natural roll by its size, so ``apply="confident"`` does not
apply it (:func:`mocapqa.twist.confidence.decide`, rule ``"natural_roll"``); it is listed with
the reason.

The natural level is the ``PERCENTILE``-th percentile of the absolute event jumps the detector
reads, with its defaults, on the clean *fit* takes of a rig (never the held-out takes, never a
take with real errors), per rig family (:func:`mocapqa.limits.rig.rig_family`) and limb
segment. It is stored in ``data/twist/natural_roll.json`` beside the calibration and written by
``mocapqa bench twist --fit-natural-roll``. A rig or segment with no event on its clean fit takes
has no stored level and falls back to :data:`mocapqa.twist.confidence.MIN_LEVEL_DEG`.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError
from mocapqa.twist.angles import ChainGeometry
from mocapqa.twist.detect import Detection
from mocapqa.twist.shipped import shipped_json

__all__ = [
    "NATURAL_ROLL_FILE",
    "PERCENTILE",
    "NaturalRoll",
    "default_natural_roll",
    "event_jumps_deg",
    "fit_natural_roll",
    "natural_key",
]

NATURAL_ROLL_FILE = "natural_roll.json"
"""Name of the stored natural roll levels in the package's ``data/twist`` folder."""
PERCENTILE = 99.0
"""Percentile of the clean fit takes' event jumps that is a rig segment's natural level."""


def natural_key(family: str, segment: str) -> str:
    """A rig family's segment as a key of :attr:`NaturalRoll.levels_deg`: ``"bandai/upper_arm"``."""
    return f"{family}/{segment}"


def event_jumps_deg(
    detection: Detection, geometries: Sequence[ChainGeometry]
) -> dict[str, FloatArray]:
    """The absolute jump of every event of a detection, degrees, by limb segment.

    Parameters
    ----------
    detection : Detection
        A robust detection (with ``jumps``) of the chains ``geometries``.
    geometries : sequence of ChainGeometry

    Returns
    -------
    dict
        Segment → absolute jumps (degrees) of its chains' events; a segment with no event is
        absent.
    """
    if detection.jumps is None:
        return {}
    rows, cols = np.nonzero(detection.candidates)
    jumps = np.rad2deg(np.abs(detection.jumps[rows, cols]))
    segments = np.array([g.chain.segment for g in geometries], dtype=object)[cols]
    return {str(s): jumps[segments == s] for s in np.unique(segments)} if len(cols) else {}


@dataclass(frozen=True, slots=True)
class NaturalRoll:
    """Natural roll levels per rig family and segment.

    Parameters
    ----------
    levels_deg : dict
        :func:`natural_key` → the :data:`PERCENTILE`-th percentile of the absolute event jumps
        on clean fit takes, degrees.
    p95_deg : dict
        The same keys → the 95th percentile (reported, not used by the rule).
    events : dict
        The same keys → how many events the levels were read from.
    fitted_on : str
        Which takes the levels were read from.
    """

    levels_deg: dict[str, float] = field(default_factory=dict)
    p95_deg: dict[str, float] = field(default_factory=dict)
    events: dict[str, int] = field(default_factory=dict)
    fitted_on: str = ""

    def level_deg(self, family: str, segment: str) -> float:
        """The natural level of a rig family's segment, degrees; 0 when none is stored."""
        return float(self.levels_deg.get(natural_key(family, segment), 0.0))

    def to_json(self) -> dict[str, Any]:
        """The levels as a JSON-ready dict."""
        return {
            "percentile": PERCENTILE,
            "fitted_on": self.fitted_on,
            "levels_deg": {k: round(v, 3) for k, v in sorted(self.levels_deg.items())},
            "p95_deg": {k: round(v, 3) for k, v in sorted(self.p95_deg.items())},
            "events": dict(sorted(self.events.items())),
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any], source: str = "natural roll") -> NaturalRoll:
        """The levels from :meth:`to_json`'s dict.

        Raises
        ------
        InputError
            When a field is missing or not a number.
        """
        try:
            levels = {str(k): float(v) for k, v in data["levels_deg"].items()}
            p95 = {str(k): float(v) for k, v in data.get("p95_deg", {}).items()}
            events = {str(k): int(v) for k, v in data.get("events", {}).items()}
            fitted_on = str(data.get("fitted_on", ""))
        except (KeyError, TypeError, ValueError, AttributeError) as error:
            raise InputError(f"Expected natural roll levels in {source}, got {error!r}") from error
        return cls(levels, p95, events, fitted_on)


def fit_natural_roll(
    jumps: Mapping[str, Sequence[float] | FloatArray],
    fitted_on: str,
    path: Path | None = None,
) -> NaturalRoll:
    """Natural levels from the event jumps of clean fit takes, optionally written as JSON.

    Parameters
    ----------
    jumps : mapping
        :func:`natural_key` → absolute event jumps, degrees (keys with no jump are left out).
    fitted_on : str
        Description of the takes, stored with the levels.
    path : Path, optional
        Where to write the JSON.

    Returns
    -------
    NaturalRoll
    """
    kept = {k: np.asarray(v, dtype=np.float64) for k, v in jumps.items() if len(v) > 0}
    natural = NaturalRoll(
        {k: float(np.percentile(v, PERCENTILE)) for k, v in kept.items()},
        {k: float(np.percentile(v, 95.0)) for k, v in kept.items()},
        {k: len(v) for k, v in kept.items()},
        fitted_on,
    )
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(natural.to_json(), indent=2) + "\n", encoding="utf-8")
    return natural


@cache
def default_natural_roll() -> NaturalRoll:
    """The shipped levels (``mocapqa/data/twist/natural_roll.json``), read once."""
    return NaturalRoll.from_json(*shipped_json(NATURAL_ROLL_FILE))
