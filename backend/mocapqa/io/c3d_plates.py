"""Force plates of a C3D file: each plate's corners and the load along its normal over time.

Conventions
-----------
* The file is checked by :func:`mocapqa.io.c3d.inspect_c3d` and
  :func:`mocapqa.io.c3d.check_for_ezc3d` before ezc3d opens it (ezc3d is C++: malformed
  parameters can crash it), then read with ``ezc3d.c3d(path, extract_forceplat_data=True)``,
  which turns the plates' analog channels (``FORCE_PLATFORM:CHANNEL``, ``TYPE``,
  ``CAL_MATRIX``) into forces in the lab frame, newtons, at the analog rate.
* ``corners`` are ``FORCE_PLATFORM:CORNERS`` ``(4, 3)``, in the point unit (``POINT:UNITS``,
  the unit of the markers): the plate's top surface in the markers' frame.
* ``load`` is the force along the plate's normal (the corners' plane), newtons, one value per
  analog sample: positive when something presses on the plate, whatever the sign convention
  of the file (the sign is the one of the largest excursion from the baseline: a foot only
  pushes). The baseline is the mean over ``FORCE_PLATFORM:ZERO`` (first and last frame,
  1-based point frames) when the file gives a valid range; ezc3d does not subtract it, and the
  c3d.org gait samples read 21–32 N (``Eb015pr``) and −9 to −13 N (``DEC_INT``) unloaded.
* A plate whose load is the same value at every sample (a channel left unconnected:
  ``parameterOverflow.c3d``'s third plate reads −1448 N throughout) is ``flat``; it gives no
  contact.
* Analog sample ``k`` belongs to point frame ``k // samples_per_frame`` and lies
  ``k / analog_rate`` seconds after the take's first point frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError, ParseError
from mocapqa.io.c3d_layout import check_for_ezc3d, inspect_c3d

__all__ = ["ForcePlate", "ForcePlates", "read_force_plates"]


@dataclass(frozen=True, slots=True)
class ForcePlate:
    """One force plate of a take.

    Parameters
    ----------
    index : int
        0-based position in ``FORCE_PLATFORM`` (plate ``index + 1`` of the file).
    corners : ndarray, shape (4, 3)
        The plate's corners, point units, in ``CORNERS`` order (around the plate).
    load : ndarray, shape (S,)
        Force along the plate's normal, newtons, baseline removed, positive when loaded; one
        value per analog sample.
    baseline : float
        The value subtracted (newtons along the normal, before the sign was set).
    flat : bool
        True when the signal is one value throughout (no usable load).
    """

    index: int
    corners: FloatArray
    load: FloatArray
    baseline: float
    flat: bool


@dataclass(frozen=True, slots=True)
class ForcePlates:
    """The force plates of a take, and the clocks that tie them to its point frames.

    Parameters
    ----------
    plates : tuple of ForcePlate
        Empty when the file declares none.
    analog_rate : float
        Analog samples per second (the plates' rate).
    point_rate : float
        Point frames per second.
    length_unit : str
        The corners' unit (the point unit: "mm", "m", ...).
    """

    plates: tuple[ForcePlate, ...]
    analog_rate: float
    point_rate: float
    length_unit: str

    @property
    def samples_per_frame(self) -> int:
        """Analog samples per point frame."""
        return max(1, round(self.analog_rate / self.point_rate))


_UNITS = {"mm": "mm", "m": "m", "mete": "m", "meter": "m", "meters": "m", "cm": "cm"}


def _values(parameters: Any, group: str, name: str) -> Any:
    try:
        return parameters[group][name]["value"]
    except KeyError:
        return None


def _plate_normal(corners: FloatArray) -> FloatArray:
    """Unit normal of the plane of four corners ``(4, 3)`` (sign arbitrary)."""
    normal = np.cross(corners[2] - corners[0], corners[3] - corners[1])
    length = float(np.linalg.norm(normal))
    if not length > 0:
        raise InputError(f"Expected force-plate corners spanning a plane, got {corners.tolist()}")
    unit: FloatArray = normal / length
    return unit


def _baseline(signal: FloatArray, zero: Any, per_frame: int) -> float:
    """Mean of ``signal`` over the ``ZERO`` frames (1-based, inclusive); 0 when not given."""
    if zero is None or np.size(zero) < 2:
        return 0.0
    first, last = (int(v) for v in np.ravel(zero)[:2])
    if not 1 <= first <= last:
        return 0.0
    window = signal[(first - 1) * per_frame : last * per_frame]
    return float(np.mean(window)) if window.size else 0.0


def read_force_plates(path: str | Path) -> ForcePlates:
    """Read the force plates of a C3D file.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    ForcePlates

    Raises
    ------
    ParseError
        If the file is malformed, or ezc3d cannot compute its plates' forces.
    InputError
        If a plate's corners do not span a plane.
    """
    import ezc3d

    path = Path(path)
    layout = inspect_c3d(path)
    check_for_ezc3d(layout, path)
    try:
        c3d = ezc3d.c3d(str(path), extract_forceplat_data=True)
    except Exception as e:  # ezc3d raises RuntimeError, ValueError, IndexError
        raise ParseError(f"Expected force plates ezc3d can read, got: {e}", path) from e
    parameters = c3d["parameters"]
    point_rate = float(np.ravel(_values(parameters, "POINT", "RATE"))[0])
    analog = _values(parameters, "ANALOG", "RATE")
    analog_rate = float(np.ravel(analog)[0]) if analog is not None and np.size(analog) else 0.0
    units = _values(parameters, "POINT", "UNITS")
    unit = str(units[0]).strip().lower() if units else "mm"
    length_unit = _UNITS.get(unit, unit or "unknown")
    platforms = c3d["data"].get("platform", []) if analog_rate > 0 else []
    per_frame = max(1, round(analog_rate / point_rate)) if analog_rate > 0 else 1
    zero = _values(parameters, "FORCE_PLATFORM", "ZERO")
    plates = []
    for index, platform in enumerate(platforms):
        corners = np.asarray(platform["corners"], dtype=np.float64).T
        force = np.asarray(platform["force"], dtype=np.float64).T
        normal = _plate_normal(corners)
        along = force @ normal
        finite = along[np.isfinite(along)]
        flat = finite.size == 0 or float(np.ptp(finite)) == 0.0
        baseline = _baseline(along, zero, per_frame) if not flat else float(finite[0])
        load = along - baseline
        if not flat:
            peak = int(np.nanargmax(np.abs(load)))
            load = load * np.sign(load[peak])
        plates.append(
            ForcePlate(
                index=index,
                corners=corners,
                load=np.nan_to_num(load, nan=0.0),
                baseline=baseline,
                flat=flat,
            )
        )
    return ForcePlates(tuple(plates), analog_rate, point_rate, length_unit)
