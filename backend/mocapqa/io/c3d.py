"""C3D marker takes: read through ezc3d (py-c3d where ezc3d refuses), written through ezc3d.

Conventions
-----------
* :func:`read_c3d` returns a :class:`MarkerTake`: the points as a
  :class:`~mocapqa.core.keypoints.KeypointSequence` ``(F, M, 3)`` in the file's unit
  (``POINT:UNITS``, never rescaled), at ``POINT:RATE``, NaN where a sample is missing, with the
  file's residuals ``(F, M)`` (−1 missing, 0 interpolated or filled, > 0 measured) and camera
  contribution bits beside them. Names are the point labels (``LABELS`` then ``LABELS2``…);
  an empty label is named ``*<index>`` (0-based, as Vicon names unlabelled trajectories) and a
  repeated one ``<label>#<n>`` (its n-th use), each recorded as an assumption.
* A sample is missing when its residual is negative or a coordinate is NaN (OptiTrack writes
  NaN with residual 0); its residual is −1 in the take either way.
* Before any reader sees the file, :func:`inspect_c3d` checks the header and walks the parameter
  section in Python: the magic byte, the processor type, every parameter record inside the
  section, and that the data the header declares fit in the file. ezc3d is C++: on malformed
  parameter records it can crash the process or loop for ever (found by corrupting real files),
  so it is given only files that pass these and :func:`check_for_ezc3d`; the others go to
  py-c3d, which raises instead.
* ezc3d 1.7.2 refuses MIPS (big-endian) files and some non-standard parameters (a FLOAT
  ``ANALOG:OFFSET``); those are read by py-c3d (``c3d`` on PyPI, pure Python), which reads
  both kinds but checks that header and parameters agree. A file neither reads is refused with a
  :class:`~mocapqa.errors.ParseError` giving both reasons.
* :func:`write_c3d` writes a missing sample as the standard says: zero coordinates with
  residual −1. Residuals are stored as multiples of ``|POINT:SCALE|``; a measured residual
  smaller than that step is written as one step, so 0 keeps meaning "filled". With ``source``,
  the source file is opened again and only its point data, labels, descriptions, units, rate
  and first frame are replaced: analogs, force plates, events and every other group are
  written as they were read.
"""

from __future__ import annotations

import math
import os
import struct
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError, ParseError, ShapeError, UnsupportedFormatError
from mocapqa.io.atomic import atomic_path
from mocapqa.io.guards import C3DHeader, ReadLimits, check_c3d_header, read_c3d_header
from mocapqa.io.keypoint_input import build_keypoint_sequence

__all__ = [
    "C3DEvent",
    "C3DLayout",
    "MarkerTake",
    "check_for_ezc3d",
    "inspect_c3d",
    "read_c3d",
    "write_c3d",
]

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
_TYPE_SIZES = {-1: 1, 1: 1, 2: 2, 4: 4}
# Parameters the standard defines as numbers, and names of string parameters (LABELS2… too).
_NUMERIC = frozenset(
    f"{group}:{name}"
    for group, names in {
        "POINT": "USED SCALE RATE DATA_START FRAMES",
        "ANALOG": "USED GEN_SCALE SCALE OFFSET RATE BITS",
        "FORCE_PLATFORM": "USED TYPE ZERO CORNERS ORIGIN CHANNEL CAL_MATRIX",
        "EVENT": "USED TIMES ICON_IDS GENERIC_FLAGS",
        "TRIAL": "ACTUAL_START_FIELD ACTUAL_END_FIELD CAMERA_RATE VIDEO_RATE_DIVIDER",
        "ROTATION": "USED RATE DATA_START RATIO",
    }.items()
    for name in names.split()
)
_STRINGS = frozenset({"LABELS", "DESCRIPTIONS", "UNITS", "CONTEXTS", "SUBJECTS"})
_MAX_RESIDUAL_STEPS = 255


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


@dataclass(frozen=True, slots=True)
class C3DLayout:
    """A C3D file's header and parameter section, as checked by :func:`inspect_c3d`.

    Parameters
    ----------
    header : C3DHeader
        The 512-byte header.
    parameters : dict
        ``"GROUP:NAME"`` → (type, dimensions, raw bytes) of every parameter.
    longest_description : int
        Characters in the longest group or parameter description.
    """

    header: C3DHeader
    parameters: dict[str, tuple[int, tuple[int, ...], bytes]]
    longest_description: int = 0

    def integers(self, key: str) -> list[int]:
        """An INT or BYTE parameter's values (empty when absent or of another type)."""
        kind, _, raw = self.parameters.get(key, (0, (), b""))
        if kind == 2:
            return list(struct.unpack(f"{self.header.byte_order}{len(raw) // 2}h", raw))
        if kind == 1:
            return list(raw)
        return []


def _record_error(message: str, path: Path) -> ParseError:
    return ParseError(f"Expected a well-formed C3D parameter section, got {message}", path)


def _walk_parameters(
    section: bytes, header: C3DHeader, path: Path
) -> tuple[dict[str, tuple[int, tuple[int, ...], bytes]], int]:
    """Every parameter record of the section, each checked to lie inside it, and the longest
    description."""
    order = header.byte_order
    end = len(section)
    groups: dict[int, str] = {}
    found: list[tuple[int, str, int, tuple[int, ...], bytes]] = []
    longest = 0
    pos = 4
    while pos + 2 <= end:
        name_length, group_id = struct.unpack_from("bb", section, pos)
        if name_length == 0:
            break
        name_end = pos + 2 + abs(name_length)
        if group_id == 0 or name_end + 2 > end:
            raise _record_error(f"a record at byte {pos} that is not a group or parameter", path)
        name = section[pos + 2 : name_end].decode("latin-1").strip().upper()
        (step,) = struct.unpack_from(f"{order}h", section, name_end)
        next_pos = name_end + step if step > 0 else end
        if next_pos > end:
            raise _record_error(f"record {name!r} pointing outside the section", path)
        body = name_end + 2
        if group_id < 0:
            if body + 1 > next_pos or body + 1 + section[body] > next_pos:
                raise _record_error(f"group {name!r} longer than its record", path)
            longest = max(longest, section[body])
            groups[-group_id] = name
        else:
            if body + 2 > next_pos:
                raise _record_error(f"parameter {name!r} longer than its record", path)
            kind, n_dims = struct.unpack_from("bB", section, body)
            if kind not in _TYPE_SIZES or n_dims > 7:
                raise _record_error(f"parameter {name!r} of type {kind}, {n_dims} dimensions", path)
            dims = tuple(section[body + 2 : body + 2 + n_dims])
            data_start = body + 2 + n_dims
            data_end = data_start + _TYPE_SIZES[kind] * math.prod(dims)
            if data_end + 1 > next_pos or data_end + 1 + section[data_end] > next_pos:
                raise _record_error(f"parameter {name!r} longer than its record", path)
            longest = max(longest, section[data_end])
            found.append((group_id, name, kind, dims, section[data_start:data_end]))
        if step <= 0:
            break
        pos = next_pos
    parameters: dict[str, tuple[int, tuple[int, ...], bytes]] = {}
    for group_id, name, kind, dims, raw in found:
        if group_id not in groups:
            raise _record_error(f"parameter {name!r} of a group ({group_id}) never named", path)
        parameters[f"{groups[group_id]}:{name}"] = (kind, dims, raw)
    return parameters, longest


def _check_types(layout: C3DLayout, path: Path) -> None:
    """Strings with a length, numbers where the standard has numbers (ezc3d trusts both)."""
    for key, (kind, dims, _) in layout.parameters.items():
        if kind == -1 and not dims:
            raise ParseError(
                "Expected a string parameter with dimensions, got none", path, field=key
            )
        if kind == -1 and key in _NUMERIC:
            raise ParseError("Expected a number, got a string parameter", path, field=key)
        if kind != -1 and key.split(":")[1].rstrip("0123456789") in _STRINGS:
            raise ParseError("Expected strings, got a number parameter", path, field=key)


def check_for_ezc3d(layout: C3DLayout, path: str | Path) -> None:
    """Refuse a file ezc3d 1.7.2 would crash or hang on, found by corrupting real files.

    Parameters it sizes arrays by must agree with the header and each other, strings must have
    dimensions and numbers be numbers, each analog channel needs a scale and an offset, and
    descriptions must be shorter than 128 characters (ezc3d reads the length as a signed byte).
    py-c3d, in pure Python, raises on such files instead.

    Raises
    ------
    ParseError
        Naming the parameter.
    """
    path = Path(path)
    if layout.longest_description > 127:
        raise ParseError(
            f"Expected descriptions of at most 127 characters, got {layout.longest_description}",
            path,
        )
    _check_types(layout, path)
    header = layout.header
    used = layout.integers("POINT:USED")
    if used and used[0] != header.n_points:
        raise ParseError(
            f"Expected POINT:USED to equal the header's point count {header.n_points}, "
            f"got {used[0]}",
            path,
            field="POINT:USED",
        )
    analog_used = layout.integers("ANALOG:USED")
    channels = analog_used[0] if analog_used else 0
    if channels < 0 or (channels and header.analog_per_frame % channels):
        raise ParseError(
            f"Expected ANALOG:USED to divide the header's {header.analog_per_frame} analog "
            f"samples per frame, got {channels}",
            path,
            field="ANALOG:USED",
        )
    if channels == 0 and header.analog_per_frame:
        raise ParseError(
            f"Expected ANALOG:USED for the header's {header.analog_per_frame} analog samples "
            "per frame, got none",
            path,
            field="ANALOG:USED",
        )
    for key in ("ANALOG:SCALE", "ANALOG:OFFSET"):  # ezc3d crashes on a channel without them
        if channels:
            kind, dims, _ = layout.parameters.get(key, (0, (0,), b""))
            if math.prod(dims) < channels:
                raise ParseError(
                    f"Expected {key} for each of the {channels} analog channels, "
                    f"got {math.prod(dims)}",
                    path,
                    field=key,
                )
    for group in ("POINT", "ANALOG"):
        kind, dims, _ = layout.parameters.get(f"{group}:LABELS", (-1, (0, 0), b""))
        if kind != -1 or len(dims) > 2:
            raise ParseError(
                f"Expected {group}:LABELS as a list of strings, got type {kind} of {len(dims)} "
                "dimensions",
                path,
                field=f"{group}:LABELS",
            )


def inspect_c3d(path: str | Path) -> C3DLayout:
    """Check a C3D file's header and parameter section in Python, before any reader.

    Parameters
    ----------
    path : str or Path
        The C3D file to check.

    Returns
    -------
    C3DLayout
        The header and the raw parameters.

    Raises
    ------
    ParseError
        On an empty or truncated file, a missing magic byte, an unknown processor type, a
        parameter record that does not fit its section, or data the header declares beyond
        the end of the file (what only ezc3d cannot take: :func:`check_for_ezc3d`).
    """
    path = Path(path)
    header = read_c3d_header(path)
    start = (header.parameter_block - 1) * 512
    # The records end where the data start (the section's block count is wrong in some files).
    data_start = (header.data_block - 1) * 512
    size = (data_start if header.data_bytes else header.file_size) - start
    try:
        with path.open("rb") as handle:
            handle.seek(start)
            section = handle.read(size)
    except OSError as e:
        raise ParseError(f"Expected a readable file, got {e.strerror or e}", path) from e
    parameters, longest = _walk_parameters(section, header, path)
    return C3DLayout(header, parameters, longest)


# Reading --------------------------------------------------------------------------------------


class _Parameters:
    """Parameter values from either reader: ``GROUP:NAME`` → list of values."""

    def __init__(self, get: Callable[[str, str], list[Any]]) -> None:
        self._get = get

    def strings(self, group: str, name: str) -> list[str]:
        values = self._get(group, name)
        return [str(v).strip() for v in values]

    def numbers(self, group: str, name: str) -> list[float]:
        try:
            return [float(v) for v in self._get(group, name)]
        except (TypeError, ValueError):
            return []

    def labels(self, group: str, count: int) -> list[str]:
        """``LABELS``, then ``LABELS2``, ``LABELS3``… up to ``count``."""
        out = self.strings(group, "LABELS")
        extra = 2
        while len(out) < count:
            more = self.strings(group, f"LABELS{extra}")
            if not more:
                break
            out += more
            extra += 1
        return out[:count]


def _ezc3d_parameters(parameters: Any) -> _Parameters:
    def get(group: str, name: str) -> list[Any]:
        if group not in parameters or name not in parameters[group]:
            return []
        value = parameters[group][name]["value"]
        return list(np.ravel(value)) if isinstance(value, np.ndarray) else list(value)

    return _Parameters(get)


def _pyc3d_parameters(reader: Any) -> _Parameters:
    def get(group: str, name: str) -> list[Any]:
        try:
            return values(group, name)
        except Exception:  # py-c3d raises on a value it cannot convert: read as absent
            return []

    def values(group: str, name: str) -> list[Any]:
        param = reader.get(f"{group}:{name}")
        if param is None:
            return []
        if param.bytes_per_element == -1:
            if len(param.dimensions) <= 1:
                return [param.string_value]
            return list(param.string_array.ravel())
        if not param.dimensions:
            if param.bytes_per_element == 4:
                return [param.float_value]
            return [param.int16_value if param.bytes_per_element == 2 else param.int8_value]
        if param.bytes_per_element == 4:
            return list(np.ravel(param.float_array))
        return list(np.ravel(param.int_array))

    return _Parameters(get)


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


def _unit(parameters: _Parameters) -> tuple[str, list[str]]:
    stored = next(iter(parameters.strings("POINT", "UNITS")), "")
    unit = _UNITS.get(stored.lower())
    if unit is not None:
        return unit, []
    if not stored:
        return "unknown", ["POINT:UNITS is empty: length unit unknown"]
    return "unknown", [f"POINT:UNITS {stored!r} is not a length unit: length unit unknown"]


def _events(parameters: _Parameters, rate: float, first_frame: int) -> tuple[C3DEvent, ...]:
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


def _build(
    path: Path,
    xyz: FloatArray,
    residuals: FloatArray,
    camera_masks: IntArray,
    parameters: _Parameters,
    header_rate: float,
    first_frame: int,
    reader: str,
) -> MarkerTake:
    """A MarkerTake from ``(F, M, 3)`` coordinates and ``(F, M)`` residuals and masks."""
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


def _from_ezc3d(path: Path, layout: C3DLayout, c3d: Any) -> MarkerTake:
    data = c3d["data"]
    points = data["points"]  # (4, M, F)
    meta = data["meta_points"]
    xyz = np.asarray(points[:3], dtype=np.float64).transpose(2, 1, 0)
    residuals = np.asarray(meta["residuals"][0], dtype=np.float64).T
    masks = np.asarray(meta["camera_masks"], dtype=bool)  # (7, M, F): bit k, camera k + 1
    if masks.size:
        bits = (1 << np.arange(masks.shape[0])).astype(np.uint8)  # at most 127
        camera = np.einsum("k,kmf->fm", bits, masks.view(np.uint8))
    else:
        camera = np.zeros(residuals.shape, dtype=np.uint8)
    first_frame = int(c3d["header"]["points"]["first_frame"]) + 1
    return _build(
        path,
        xyz,
        residuals,
        camera.astype(np.intp),
        _ezc3d_parameters(c3d["parameters"]),
        layout.header.frame_rate,
        first_frame,
        "ezc3d",
    )


def _open_pyc3d(path: Path) -> tuple[int, list[FloatArray], _Parameters]:
    import c3d as pyc3d

    with path.open("rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reader = pyc3d.Reader(handle)
        first_frame = int(reader.first_frame)
        frames = [points for _, points, _ in reader.read_frames(copy=True)]
        parameters = _pyc3d_parameters(reader)
    return first_frame, frames, parameters


def _from_pyc3d(
    path: Path, layout: C3DLayout, first_frame: int, frames: list[FloatArray], parameters: Any
) -> MarkerTake:
    n_points = layout.header.n_points
    block = np.stack(frames) if frames else np.zeros((0, n_points, 5))  # (F, M, 5)
    residuals = block[..., 3].astype(np.float64)
    camera = np.where(residuals < 0, 0, block[..., 4]).astype(np.intp)  # the bits, as stored
    return _build(
        path,
        block[..., :3].astype(np.float64),
        residuals,
        camera,
        parameters,
        layout.header.frame_rate,
        first_frame,
        "py-c3d",
    )


def _reason(error: BaseException) -> str:
    text = " ".join(str(error).split())[:200]
    return text or type(error).__name__


def read_c3d(path: str | Path, limits: ReadLimits | None = None) -> MarkerTake:
    """Read a C3D file's points, residuals, camera masks, labels, events and analog channels.

    Parameters
    ----------
    path : str or Path
        The file.
    limits : ReadLimits, optional
        Refuse a take whose header declares more frames × points than
        ``limits.max_frame_points``, or more data bytes than ``limits.max_unpacked_bytes``,
        before it is parsed; no limits when None.

    Returns
    -------
    MarkerTake

    Raises
    ------
    ParseError
        On a malformed file (see :func:`inspect_c3d`), or one that neither ezc3d nor py-c3d
        reads (the message gives both reasons).
    TooLargeError
        When the header declares a take beyond ``limits``.
    """
    path = Path(path)
    layout = inspect_c3d(path)
    if limits is not None:
        check_c3d_header(layout.header, path.name, limits)
    problems = []
    try:
        if layout.header.processor == 86:
            raise UnsupportedFormatError("MIPS processor type not supported")
        check_for_ezc3d(layout, path)
    except InputError as e:
        problems.append(f"ezc3d: {getattr(e, 'message', str(e))}")
    else:
        import ezc3d

        try:
            c3d = ezc3d.c3d(str(path))
        except Exception as e:  # ezc3d raises RuntimeError, ValueError, OSError, IndexError
            problems.append(f"ezc3d: {_reason(e)}")
        else:
            return _from_ezc3d(path, layout, c3d)
    try:
        opened = _open_pyc3d(path)
    except Exception as e:  # py-c3d's consistency checks are assertions
        problems.append(f"py-c3d: {_reason(e)}")
    else:
        return _from_pyc3d(path, layout, *opened)
    raise ParseError(
        "Expected a C3D file that ezc3d or py-c3d reads, got one both refuse "
        f"({'; '.join(problems)})",
        path,
    )


# Writing --------------------------------------------------------------------------------------


def _set_in_255s(c3d: Any, key: str, values: list[str]) -> None:
    """``POINT:<key>``, then ``<key>2``, ``<key>3``… 255 values each (a dimension is a byte)."""
    point = c3d["parameters"]["POINT"]
    for index in range(max(1, math.ceil(len(values) / 255))):
        name = key if index == 0 else f"{key}{index + 1}"
        chunk = values[255 * index : 255 * (index + 1)]
        if name in point:
            point[name]["value"] = chunk
        else:
            c3d.add_parameter("POINT", name, chunk)


def _trim_analog_labels(parameters: Any, channels: int) -> None:
    """Keep the labels of the channels used: ezc3d writes only as many as there are channels
    (c3d.org's samples list more labels than channels)."""
    analog = parameters["ANALOG"]
    extra, kept = 1, 0
    while (key := "LABELS" if extra == 1 else f"LABELS{extra}") in analog:
        labels = list(analog[key]["value"])
        analog[key]["value"] = labels[: max(channels - kept, 0)]
        kept += len(analog[key]["value"])
        extra += 1


def _residual_step(c3d: Any, residuals: FloatArray) -> float:
    """``|POINT:SCALE|``: the source's, or for a new file one that keeps the largest residual."""
    point = c3d["parameters"]["POINT"]
    scale = np.ravel(point["SCALE"]["value"])
    if scale.size and float(scale[0]) != 0 and point["USED"]["value"][0]:
        # ezc3d writes floats: an integer file's positive scale becomes negative.
        point["SCALE"]["value"] = np.array([-abs(float(scale[0]))])
        return abs(float(scale[0]))
    largest = float(residuals.max(initial=0.0))
    step = largest / _MAX_RESIDUAL_STEPS if largest > 0 else 1.0
    point["SCALE"]["value"] = np.array([-step])
    return step


def _check_take(take: MarkerTake) -> None:
    shape = take.points.positions.shape[:2]
    for name, array in (("residuals", take.residuals), ("camera_masks", take.camera_masks)):
        if np.shape(array) != shape:
            raise ShapeError(f"Expected `{name}` of shape {shape}, got {np.shape(array)}")


def write_c3d(path: str | Path, take: MarkerTake, source: str | Path | None = None) -> None:
    """Write a marker take as C3D, whole or not at all (:mod:`mocapqa.io.atomic`).

    Parameters
    ----------
    path : str or Path
        The output.
    take : MarkerTake
        Points ``(F, M, 3)`` (NaN missing), residuals ``(F, M)``, camera masks ``(F, M)``,
        labels, descriptions, unit, rate, first frame; events are written when there is no
        ``source``.
    source : str or Path, optional
        The C3D the take was read from: its analogs, force plates, events and other groups
        are written unchanged. It must hold the take's number of points and frames.

    Raises
    ------
    InputError
        When ``source`` does not match the take (points, frames), or ezc3d cannot write it
        (a rate that no longer matches the source's analog samples).
    UnsupportedFormatError
        When ezc3d cannot open ``source`` (:func:`read_c3d` read it with py-c3d): write
        without it.
    ShapeError
        When the residuals or camera masks do not match the points.
    """
    _check_take(take)
    seq = take.points
    if source is not None:
        c3d = _source_c3d(Path(source), seq.n_keypoints, seq.n_frames)
    else:
        c3d = _new_c3d(take.events)
    _set_point_parameters(c3d, take, keep_unit=source is not None)
    _set_point_data(c3d, take)
    with atomic_path(path) as temporary:
        # ezc3d adds ".c3d" to a name without it, so it writes beside the temporary file.
        named = temporary.with_name(temporary.name + ".c3d")
        try:
            try:
                c3d.write(str(named))
            except (RuntimeError, ValueError, TypeError) as e:
                raise InputError(f"Expected a take ezc3d can write, got {_reason(e)}") from e
            os.replace(named, temporary)
        finally:
            named.unlink(missing_ok=True)


def _source_c3d(source: Path, n_points: int, n_frames: int) -> Any:
    """The ezc3d object of the C3D a take was read from, checked against the take."""
    import ezc3d

    layout = inspect_c3d(source)
    if layout.header.processor == 86:
        raise UnsupportedFormatError(
            f"Expected a source C3D that ezc3d reads, got a MIPS file: {source.name}"
        )
    check_for_ezc3d(layout, source)
    try:
        c3d = ezc3d.c3d(str(source))
    except Exception as e:  # as in read_c3d
        raise UnsupportedFormatError(
            f"Expected a source C3D that ezc3d reads, got {source.name} ({_reason(e)})"
        ) from e
    held = c3d["data"]["points"].shape
    if held[1:] != (n_points, n_frames):
        raise InputError(
            f"Expected the take to have the source's {held[1]} points and {held[2]} frames, "
            f"got {n_points} points and {n_frames} frames ({source.name})"
        )
    _trim_analog_labels(c3d["parameters"], c3d["data"]["analogs"].shape[1])
    return c3d


def _new_c3d(events: Sequence[C3DEvent]) -> Any:
    """A new ezc3d object holding ``events``."""
    import ezc3d

    c3d = ezc3d.c3d()
    for event in events:
        minutes = math.floor(event.time_s / 60.0)
        c3d.add_event(
            [float(minutes), event.time_s - 60.0 * minutes],
            context=event.context,
            label=event.label,
        )
    return c3d


def _set_point_parameters(c3d: Any, take: MarkerTake, *, keep_unit: bool) -> None:
    """``POINT`` labels, descriptions, unit (kept from a source when the take's is unknown),
    rate, and the header's first frame."""
    seq = take.points
    n_points = seq.n_keypoints
    point = c3d["parameters"]["POINT"]
    _set_in_255s(c3d, "LABELS", list(seq.names))
    if n_points <= 255:  # ezc3d 1.7.2 writes no POINT:DESCRIPTIONS for more points
        descriptions = list(take.descriptions[:n_points])
        point["DESCRIPTIONS"]["value"] = descriptions + [""] * (n_points - len(descriptions))
    if seq.length_unit != "unknown" or not keep_unit:
        point["UNITS"]["value"] = [seq.length_unit]
    point["RATE"]["value"] = np.array([seq.fps])
    c3d["header"]["points"]["first_frame"] = take.first_frame - 1


def _set_point_data(c3d: Any, take: MarkerTake) -> None:
    """Positions, residuals (and ``POINT:SCALE``) and camera masks of the points."""
    seq = take.points
    missing = np.asarray(np.isnan(seq.positions).any(axis=2), dtype=bool)  # (F, M)
    residuals = np.asarray(take.residuals, dtype=np.float64)
    step = _residual_step(c3d, np.where(missing, 0.0, residuals))
    # Whole steps of |POINT:SCALE|: a measured residual stays > 0, a filled one 0, missing −1.
    steps = np.clip(np.round(residuals / step), 1, _MAX_RESIDUAL_STEPS)
    written = np.where(residuals > 0, steps * step, 0.0)
    written = np.where(missing, -1.0, written)
    block = np.ones((4, seq.n_keypoints, seq.n_frames))
    block[:3] = np.where(missing[..., None], 0.0, seq.positions).transpose(2, 1, 0)
    data = c3d["data"]
    data["points"] = block
    data["meta_points"]["residuals"] = written.T[None]
    bits = np.left_shift(1, np.arange(7, dtype=np.intp))
    masks = (np.asarray(take.camera_masks, dtype=np.intp).T[None] & bits[:, None, None]) != 0
    data["meta_points"]["camera_masks"] = masks & ~missing.T[None]
