"""A C3D file's header and parameter section, checked in Python before any reader sees it.

Conventions
-----------
* :func:`inspect_c3d` checks the header and walks the parameter section: the magic byte, the
  processor type, every parameter record inside the section, and that the data the header
  declares fit in the file.
* ezc3d is C++: on malformed parameter records it can crash the process or loop for ever (found
  by corrupting real files), so it is given only files that pass these and
  :func:`check_for_ezc3d`; the others go to py-c3d, which raises instead.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from pathlib import Path

from mocapqa.errors import ParseError
from mocapqa.io.guards import C3DHeader, read_c3d_header

__all__ = ["C3DLayout", "check_for_ezc3d", "inspect_c3d"]

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
