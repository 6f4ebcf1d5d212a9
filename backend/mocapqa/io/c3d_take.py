"""A C3D marker take, and how it is built from either reader's arrays and parameters.

Conventions
-----------
* The points are a :class:`~mocapqa.core.keypoints.KeypointSequence` ``(F, M, 3)`` in the
  file's unit (``POINT:UNITS``, never rescaled), at ``POINT:RATE``, NaN where a sample is
  missing, with the file's residuals ``(F, M)`` (−1 missing, 0 interpolated or filled, > 0
  measured) and camera contribution bits beside them. Names are the point labels (``LABELS``
  then ``LABELS2``…); an empty label is named ``*<index>`` (0-based, as Vicon names unlabelled
  trajectories) and a repeated one ``<label>#<n>`` (its n-th use), each recorded as an
  assumption.
* A sample is missing when its residual is negative or a coordinate is NaN (OptiTrack writes
  NaN with residual 0); its residual is −1 in the take either way.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import ParseError
from mocapqa.io.c3d_parameters import C3DParameters
from mocapqa.io.keypoint_input import build_keypoint_sequence

__all__ = ["C3DEvent", "MarkerTake", "build_marker_take"]

_UNITS = {
    "mm": "mm",
    "millimeter": "mm",
    "millimeters": "mm",
    "millimetre": "mm",
    "cm": "cm",
    "centimeter": "cm",
    "centimeters": "cm",
    "m": "m",
    "mete": "m",  # a 4-character field cut from "meter" (c3d.org sample 15)
    "meter": "m",
    "meters": "m",
    "metre": "m",
    "metres": "m",
    "in": "in",
    "inch": "in",
    "inches": "in",
}


@dataclass(frozen=True, slots=True)
class C3DEvent:
    """One entry of the file's ``EVENT`` group.

    Parameters
    ----------
    label : str
        ``EVENT:LABELS`` ("Foot Strike").
    context : str
        ``EVENT:CONTEXTS`` ("Left", "Right", "General"), "" where none.
    time_s : float
        ``EVENT:TIMES`` as seconds (minutes × 60 + seconds), on the file's clock.
    frame : int
        The frame index, 0-based from the take's first frame: ``round(time_s × rate) −
        (first_frame − 1)`` (frame numbers count from 1 at time 0); may fall outside the take.
    """

    label: str
    context: str
    time_s: float
    frame: int


@dataclass(frozen=True, slots=True)
class MarkerTake:
    """A C3D take: its points as a keypoint sequence, with what C3D records beside them.

    Parameters
    ----------
    points : KeypointSequence
        Positions ``(F, M, 3)`` in ``POINT:UNITS``, NaN where missing; names are the point
        labels; fps is ``POINT:RATE``; ``source_format`` "c3d"; confidence 1 where present, 0
        where missing; ``start_frame`` is ``first_frame``.
    residuals : ndarray, shape (F, M)
        The file's residuals, file units: −1 where missing, 0 where the sample was
        interpolated or filled, > 0 measured.
    camera_masks : ndarray of int, shape (F, M)
        Camera contribution bits (bit k: camera k + 1 of 7), 0 where the file has none.
    descriptions : tuple of str
        ``POINT:DESCRIPTIONS`` per point, "" where none.
    first_frame : int
        The file's first frame number (1-based, as stored).
    events : tuple of C3DEvent
        The ``EVENT`` group.
    analog_rate : float or None
        ``ANALOG:RATE``, samples per second; None without analog channels.
    analog_labels : tuple of str
        ``ANALOG:LABELS`` (then ``LABELS2``…) of the channels used.
    reader : str
        "ezc3d" or "py-c3d".
    """

    points: KeypointSequence
    residuals: FloatArray
    camera_masks: IntArray
    descriptions: tuple[str, ...]
    first_frame: int
    events: tuple[C3DEvent, ...]
    analog_rate: float | None
    analog_labels: tuple[str, ...]
    reader: str


def _point_names(labels: Sequence[str], count: int) -> tuple[tuple[str, ...], list[str]]:
    """Unique names for ``count`` points from their labels, and what was renamed."""
    names: list[str] = []
    notes: list[str] = []
    seen: dict[str, int] = {}
    for index in range(count):
        label = labels[index] if index < len(labels) else ""
        name = label or f"*{index}"
        if not label:
            notes.append(f"point {index} has no label: named {name!r}")
        if name in seen:
            seen[name] += 1
            renamed = f"{name}#{seen[name]}"
            notes.append(f"label {name!r} repeats (point {index}): named {renamed!r}")
            name = renamed
        seen.setdefault(name, 1)
        names.append(name)
    return tuple(names), notes


def _unit(parameters: C3DParameters) -> tuple[str, list[str]]:
    stored = next(iter(parameters.strings("POINT", "UNITS")), "")
    unit = _UNITS.get(stored.lower())
    if unit is not None:
        return unit, []
    if not stored:
        return "unknown", ["POINT:UNITS is empty: length unit unknown"]
    return "unknown", [f"POINT:UNITS {stored!r} is not a length unit: length unit unknown"]


def _events(parameters: C3DParameters, rate: float, first_frame: int) -> tuple[C3DEvent, ...]:
    labels = parameters.strings("EVENT", "LABELS")
    contexts = parameters.strings("EVENT", "CONTEXTS")
    times = parameters.numbers("EVENT", "TIMES")
    used = parameters.numbers("EVENT", "USED")
    count = min(len(labels), len(times) // 2, int(used[0]) if used else len(labels))
    events = []
    for i in range(count):
        time_s = 60.0 * times[2 * i] + times[2 * i + 1]
        if not math.isfinite(time_s):
            continue
        frame = round(time_s * rate) - (first_frame - 1)
        context = contexts[i] if i < len(contexts) else ""
        events.append(C3DEvent(labels[i], context, time_s, frame))
    return tuple(events)


def build_marker_take(
    path: Path,
    xyz: FloatArray,
    residuals: FloatArray,
    camera_masks: IntArray,
    parameters: C3DParameters,
    header_rate: float,
    first_frame: int,
    reader: str,
) -> MarkerTake:
    """A MarkerTake from ``(F, M, 3)`` coordinates and ``(F, M)`` residuals and masks.

    Parameters
    ----------
    path : Path
        The file, for messages and the sequence's source.
    xyz : ndarray, shape (F, M, 3)
        Coordinates in ``POINT:UNITS``, NaN where a reader found none.
    residuals : ndarray, shape (F, M)
        The file's residuals: negative where missing.
    camera_masks : ndarray of int, shape (F, M)
        Camera contribution bits.
    parameters : C3DParameters
        The file's parameters.
    header_rate : float
        The header's frame rate, frames per second, used when ``POINT:RATE`` is not above 0.
    first_frame : int
        The file's first frame number (1-based).
    reader : str
        "ezc3d" or "py-c3d".

    Returns
    -------
    MarkerTake

    Raises
    ------
    ParseError
        When neither ``POINT:RATE`` nor the header gives a frame rate above 0.
    """
    n_points = xyz.shape[1]
    names, notes = _point_names(parameters.labels("POINT", n_points), n_points)
    descriptions = parameters.strings("POINT", "DESCRIPTIONS")[:n_points]
    descriptions += [""] * (n_points - len(descriptions))
    rates = parameters.numbers("POINT", "RATE")
    rate = rates[0] if rates and math.isfinite(rates[0]) and rates[0] > 0 else header_rate
    if not (math.isfinite(rate) and rate > 0):
        raise ParseError(f"Expected a frame rate above 0, got {rate:g}", path, field="POINT:RATE")
    unit, unit_notes = _unit(parameters)
    missing = np.isnan(xyz).any(axis=2) | (residuals < 0)
    positions = np.where(missing[..., None], np.nan, xyz)
    residuals = np.where(missing, -1.0, residuals)
    camera_masks = np.where(missing, 0, camera_masks)  # a missing sample's word is all ones
    analog_used = parameters.numbers("ANALOG", "USED")
    channels = int(analog_used[0]) if analog_used else 0
    analog_rates = parameters.numbers("ANALOG", "RATE")
    analog_rate = analog_rates[0] if channels and analog_rates else None
    points = build_keypoint_sequence(
        path,
        names,
        positions,
        (~missing).astype(np.float64),
        rate,
        length_unit=unit,
        n_dims=3,
        source_format="c3d",
        assumptions=notes + unit_notes,
        start_frame=first_frame,
    )
    return MarkerTake(
        points=points,
        residuals=residuals,
        camera_masks=camera_masks,
        descriptions=tuple(descriptions),
        first_frame=first_frame,
        events=_events(parameters, rate, first_frame),
        analog_rate=analog_rate,
        analog_labels=tuple(parameters.labels("ANALOG", channels)),
        reader=reader,
    )
