"""Cheap checks that refuse a hostile take before a reader pays for it.

A reader's cost grows with what the file *claims* (a frame count, an array shape, a nesting
depth, one enormous line), not only with its size on disk: a 467 KB ``.npz`` can unpack to
half a gigabyte, a 100 MB BVH header can declare a million joints. :func:`check_take_input`
looks at the bytes with C-speed scans (``bytes.find``/``count``, NumPy over fixed-size chunks,
the ``.npy`` headers inside a zip directory) and raises :class:`~mocapqa.errors.TooLargeError`
naming the limit before any reader runs; :func:`check_take_size` is the backstop after the
read, for the formats whose frame count is only known by parsing (the JSON formats).

Frames × points before parsing, by format: BVH from ``Frames:`` and the joints of the header;
``.npy``/``.npz`` from the array headers; TRC from its marker-name line times its data lines;
the long CSVs (keypoint CSV, MediaPipe CSV), one line per frame and point, from their data
lines (a lower bound of frames × points: the read take spans every frame number between the
first and the last). Lines are counted with ``bytes.count`` in 1 MB chunks; blank lines count
as data lines, so the estimate errs toward refusing, by the number of blank lines.

Marker takes (TRC, C3D) are also refused over ``max_markers`` markers, from the TRC's
marker-name line (its first lines split as the reader splits them, at a lone carriage return
too) or the C3D header's point count: the marker check's pair statistics cost time in
proportion to the number of marker pairs.

The limits are parameters (:class:`ReadLimits`); the server builds them from its settings.
"""

from __future__ import annotations

import codecs
import lzma
import math
import re
import struct
import tokenize
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import numpy as np

from mocapqa.errors import ParseError, TooLargeError

__all__ = [
    "JSON_FORMATS",
    "TEXT_FORMATS",
    "ZIP_READ_ERRORS",
    "C3DHeader",
    "NpyHeader",
    "ReadLimits",
    "check_c3d_header",
    "check_frame_points",
    "check_json_depth",
    "check_line_length",
    "check_marker_count",
    "check_take_input",
    "check_take_size",
    "json_nesting",
    "read_c3d_header",
    "read_npy_header",
]

TEXT_FORMATS = frozenset(
    {"bvh", "trc", "csv", "mediapipe-csv", "mediapipe-json", "mediapipe-pbtxt", "json", "openpose"}
)
"""Formats read as text lines (their line length is limited)."""
JSON_FORMATS = frozenset({"json", "mediapipe-json", "openpose"})
"""Formats parsed as JSON documents (their nesting depth is limited)."""

ZIP_READ_ERRORS: tuple[type[Exception], ...] = (
    zipfile.BadZipFile,
    zipfile.LargeZipFile,
    OSError,  # damaged bzip2 data among others
    EOFError,
    ValueError,
    RuntimeError,  # an encrypted member ("password required"); NotImplementedError, a
    # RuntimeError, for a compression method zipfile lacks (Deflate64, method 9)
    zlib.error,  # damaged deflate data
    lzma.LZMAError,  # damaged LZMA data
)
"""What opening or reading a member of a damaged or unsupported zip (``.npz``) raises."""

_CHUNK = 1 << 20
# Keywords in any case, as the reader takes them.
_JOINT = re.compile(rb"^[ \t]*(?:ROOT|JOINT)[ \t]", re.MULTILINE | re.IGNORECASE)
_MOTION = re.compile(rb"^[ \t]*MOTION[ \t\r]*$", re.MULTILINE | re.IGNORECASE)
_FRAMES = re.compile(rb"\s*FRAMES[ \t]*:([^\n]*)", re.IGNORECASE)
_TRC_LABEL = re.compile(r"^[XYZ]\d+$", re.IGNORECASE)
_OPEN = np.zeros(256, dtype=np.int8)
_OPEN[[ord("["), ord("{")]] = 1
_OPEN[[ord("]"), ord("}")]] = -1


@dataclass(frozen=True, slots=True)
class ReadLimits:
    """Largest take a reader accepts.

    Parameters
    ----------
    max_unpacked_bytes : int
        Largest total size of the arrays inside an ``.npz``/``.npy``, bytes.
    max_frame_points : int
        Largest frames × points (joints or keypoints) of a take.
    max_joints : int
        Largest number of joints in a BVH hierarchy.
    max_markers : int
        Largest number of markers (points) of a marker take (TRC, C3D).
    max_line_bytes : int
        Longest line of a text format, bytes.
    max_json_depth : int
        Deepest nesting of arrays and objects in a JSON format.
    """

    max_unpacked_bytes: int = 200_000_000
    max_frame_points: int = 5_000_000
    max_joints: int = 500
    max_markers: int = 1000
    max_line_bytes: int = 1_000_000
    max_json_depth: int = 64


def _files(path: Path) -> list[Path]:
    if path.is_dir():
        return sorted(p for p in path.iterdir() if p.suffix.lower() == ".json" and p.is_file())
    return [path]


def check_line_length(path: Path, max_line_bytes: int) -> None:
    """Refuse a file holding a line longer than ``max_line_bytes``, reading 1 MB at a time.

    Raises
    ------
    TooLargeError
        Naming the line.
    """
    line, run = 1, 0  # the line at the chunk's start, and its bytes before the chunk
    with path.open("rb") as handle:
        while chunk := handle.read(_CHUNK):
            # Line lengths from the newline positions, with NumPy: no Python step per line.
            newlines = np.flatnonzero(np.frombuffer(chunk, dtype=np.uint8) == ord("\n"))
            lengths = np.diff(newlines, prepend=-1) - 1
            if lengths.size:
                lengths[0] += run
            over = np.flatnonzero(lengths > max_line_bytes)
            tail = run + len(chunk) if newlines.size == 0 else len(chunk) - int(newlines[-1]) - 1
            if over.size or tail > max_line_bytes:
                at = line + (int(over[0]) if over.size else int(newlines.size))
                raise TooLargeError(
                    f"{path.name}, line {at}: Expected lines of at most {max_line_bytes} "
                    "bytes (setting max_line_bytes), got a longer one"
                )
            line, run = line + int(newlines.size), tail


def json_nesting(data: bytes, depth: int = 0) -> tuple[int, int]:
    """The deepest nesting of arrays and objects in ``data``, and the nesting at its end.

    Brackets are counted with NumPy, 1 MB at a time, without parsing; brackets inside strings
    count too, so the estimate errs on the side of refusing (keypoint names hold no brackets).

    Parameters
    ----------
    data : bytes
        JSON text, or a piece of it.
    depth : int
        The nesting at the start of ``data`` (the previous piece's end).

    Returns
    -------
    deepest, end : int
    """
    deepest = depth
    view = memoryview(data)
    for start in range(0, len(data), _CHUNK):
        steps = _OPEN[np.frombuffer(view[start : start + _CHUNK], dtype=np.uint8)]
        if not steps.any():
            continue
        levels = depth + np.cumsum(steps, dtype=np.int64)
        deepest, depth = max(deepest, int(levels.max())), int(levels[-1])
    return deepest, depth


def check_json_depth(path: Path, max_depth: int) -> None:
    """Refuse a JSON file nested deeper than ``max_depth``, without parsing it
    (:func:`json_nesting` over 1 MB chunks).

    Raises
    ------
    TooLargeError
        Naming the setting.
    """
    depth = 0
    with path.open("rb") as handle:
        while chunk := handle.read(_CHUNK):
            deepest, depth = json_nesting(chunk, depth)
            if deepest > max_depth:
                raise TooLargeError(
                    f"{path.name}: Expected JSON nested at most {max_depth} deep "
                    "(setting max_json_depth), got deeper"
                )


def _frame_points(header: NpyHeader, path: Path, limits: ReadLimits) -> int:
    shape = header.shape
    frame_points = shape[0] * shape[1] if len(shape) >= 2 else 0
    if frame_points > limits.max_frame_points:
        raise TooLargeError(
            f"{path.name}: Expected at most {limits.max_frame_points} frames × points "
            f"(setting max_frame_points), got {shape[0]} × {shape[1]}"
        )
    return header.n_bytes


@dataclass(frozen=True, slots=True)
class NpyHeader:
    """What a ``.npy`` header declares.

    Parameters
    ----------
    shape : tuple of int
        The array's shape (no dimension negative).
    dtype : numpy.dtype
        Its element type (never one holding Python objects).
    offset : int
        Bytes from the start of the ``.npy`` to its data.
    """

    shape: tuple[int, ...]
    dtype: np.dtype
    offset: int

    @property
    def n_bytes(self) -> int:
        """Bytes of data the header declares (Python integers: no overflow)."""
        return math.prod(self.shape) * int(self.dtype.itemsize)


# What NumPy's header reader raises on a malformed header: besides ValueError, the tokenizer's
# error (a header it retries as Python 2's), SyntaxError and RecursionError from the literal.
_HEADER_ERRORS = (
    ValueError,
    OSError,
    EOFError,
    SyntaxError,
    TypeError,
    RecursionError,
    MemoryError,
    tokenize.TokenError,
)


def _header_problem(error: BaseException) -> str:
    """What was wrong with a header, in our words (NumPy's suggest loading it unsafely)."""
    text = str(error).splitlines()[0] if str(error) else ""
    if text.startswith("Header info length"):
        return "a header longer than 10,000 bytes"
    if isinstance(error, ValueError | OSError | EOFError) and "allow_pickle" not in text:
        return text[:160] or type(error).__name__
    return "a header that is not a dictionary of shape, dtype and order"


def read_npy_header(handle: IO[bytes], path: str | Path) -> NpyHeader:
    """Read the header of the ``.npy`` at ``handle``'s position, without its data.

    Parameters
    ----------
    handle : binary file
        Positioned at the magic string; left at the start of the data.
    path : str or Path
        The file named in messages.

    Returns
    -------
    NpyHeader

    Raises
    ------
    ParseError
        On a missing magic string or a malformed header (naming the file), a negative
        dimension, or an array of Python objects (never read: that would need pickle).
    """
    start = handle.tell()
    try:
        version = np.lib.format.read_magic(handle)
        read_header = (
            np.lib.format.read_array_header_1_0
            if version == (1, 0)
            else np.lib.format.read_array_header_2_0
        )
        shape, _, dtype = read_header(handle, max_header_size=10_000)
    except _HEADER_ERRORS as e:
        raise ParseError(
            f"Expected a NumPy array header, got unreadable data ({_header_problem(e)})", path
        ) from e
    if any(n < 0 for n in shape):
        raise ParseError(f"Expected an array shape without negative sizes, got {shape}", path)
    if dtype.hasobject:
        raise ParseError(
            f"Expected an array of numbers, got an array of Python objects ({dtype}), "
            "which is not read",
            path,
        )
    return NpyHeader(tuple(int(n) for n in shape), dtype, handle.tell() - start)


def _check_arrays(path: Path, kind: str, limits: ReadLimits) -> None:
    total = 0
    if kind == "npy":
        with path.open("rb") as handle:
            total = _frame_points(read_npy_header(handle, path), path, limits)
    else:
        try:
            with zipfile.ZipFile(path) as archive:
                members = archive.infolist()
                declared = sum(m.file_size for m in members)
                if declared > limits.max_unpacked_bytes:
                    raise TooLargeError(
                        f"{path.name}: Expected at most {limits.max_unpacked_bytes} bytes "
                        f"unpacked (setting max_unpacked_bytes), got {declared}"
                    )
                for member in members:
                    if member.filename.endswith(".npy"):
                        with archive.open(member) as handle:
                            total += _frame_points(read_npy_header(handle, path), path, limits)
        except ZIP_READ_ERRORS as e:
            raise ParseError(f"Expected a readable .npz archive, got {e}", path) from e
    if total > limits.max_unpacked_bytes:
        raise TooLargeError(
            f"{path.name}: Expected at most {limits.max_unpacked_bytes} bytes of arrays "
            f"(setting max_unpacked_bytes), got {total}"
        )


def _check_bvh_header(path: Path, limits: ReadLimits) -> None:
    data = path.read_bytes()
    if data[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE):
        # The reader takes UTF-16 too; counted in its UTF-8 form.
        data = data.decode("utf-16", errors="replace").encode("utf-8")
    motion_line = _MOTION.search(data)
    motion = -1 if motion_line is None else motion_line.end()
    header_end = len(data) if motion_line is None else motion_line.start()
    joints = sum(1 for _ in _JOINT.finditer(data, 0, header_end))
    if joints > limits.max_joints:
        raise TooLargeError(
            f"{path.name}: Expected at most {limits.max_joints} joints (setting max_joints), "
            f"got {joints}"
        )
    if motion < 0:
        return
    frames = _FRAMES.match(data, motion, motion + 200)
    if frames is None:
        return
    try:
        n_frames = int(frames.group(1).strip())
    except ValueError:
        return  # the reader names the malformed line
    if n_frames * max(joints, 1) > limits.max_frame_points:
        raise TooLargeError(
            f"{path.name}: Expected at most {limits.max_frame_points} frames × joints "
            f"(setting max_frame_points), got {n_frames} × {joints}"
        )


def _count_lines(path: Path) -> int:
    """Lines of a file (a last line without a newline counts), 1 MB at a time."""
    lines, last = 0, b"\n"
    with path.open("rb") as handle:
        while chunk := handle.read(_CHUNK):
            lines += chunk.count(b"\n")
            last = chunk[-1:]
    return lines + (last != b"\n")


def _head(path: Path, n_lines: int) -> list[bytes]:
    """The first ``n_lines`` lines (their length is already bounded by ``max_line_bytes``)."""
    with path.open("rb") as handle:
        return [line for line in (handle.readline() for _ in range(n_lines)) if line]


def _long_csv_header_lines(path: Path, kind: str) -> int:
    if kind == "mediapipe-csv":
        return 1
    lines = 0  # leading comment and blank lines (the keypoint CSV's old metadata), then the header
    with path.open("rb") as handle:
        for line in handle:
            lines += 1
            if line.strip() and not line.startswith(b"#"):
                break
    return lines


def _trc_cells(text: str) -> list[str]:
    return text.split("\t") if "\t" in text else text.split()


def _trc_size(path: Path) -> tuple[int, int]:
    # Split as the reader splits (str.splitlines: "\r" and the other separators too).
    head = b"".join(_head(path, 8)).decode("utf-8", "replace").splitlines()[:8]
    if len(head) < 4:
        return 0, 0  # the reader names what is missing
    markers = sum(1 for c in _trc_cells(head[3])[2:] if c.strip())
    labels = len(head) > 4 and any(_TRC_LABEL.match(c.strip()) for c in _trc_cells(head[4]))
    start = 5 if labels else 4  # as the reader: a line of X1 Y1 Z1 ... labels, or none
    while start < len(head) and not head[start].strip():
        start += 1  # the blank line writers put before the data
    return max(_count_lines(path) - start, 0), markers


def check_marker_count(markers: int, name: str, limits: ReadLimits) -> None:
    """Refuse a marker take (TRC, C3D) of more than ``limits.max_markers`` markers.

    Parameters
    ----------
    markers : int
        The markers (points) the file declares.
    name : str
        The file named in the message.
    limits : ReadLimits

    Raises
    ------
    TooLargeError
        Naming the file, the setting and the count.
    """
    if markers > limits.max_markers:
        raise TooLargeError(
            f"{name}: Expected at most {limits.max_markers} markers (setting max_markers), "
            f"got {markers}"
        )


def check_frame_points(path: str | Path, kind: str, limits: ReadLimits) -> None:
    """Refuse a TRC, keypoint CSV or MediaPipe CSV with more than ``max_frame_points``
    frames × points, counting lines instead of parsing (see the module notes), and a TRC
    of more than ``max_markers`` markers.

    Raises
    ------
    TooLargeError
        Naming the file, the setting and the count.
    """
    path = Path(path)
    limit = limits.max_frame_points
    if kind == "trc":
        rows, markers = _trc_size(path)
        check_marker_count(markers, path.name, limits)
        if rows * markers > limit:
            raise TooLargeError(
                f"{path.name}: Expected at most {limit} frames × points (setting "
                f"max_frame_points), got {rows} data lines × {markers} markers"
            )
    elif kind in ("csv", "mediapipe-csv"):
        rows = _count_lines(path) - _long_csv_header_lines(path, kind)
        if rows > limit:
            raise TooLargeError(
                f"{path.name}: Expected at most {limit} frames × points (setting "
                f"max_frame_points), got {rows} data lines of one frame and point each"
            )


@dataclass(frozen=True, slots=True)
class C3DHeader:
    """What a C3D file's 512-byte header declares.

    Parameters
    ----------
    parameter_block : int
        1-based 512-byte block where the parameter section starts.
    parameter_blocks : int
        Blocks in the parameter section, as the section's first bytes say (some writers
        write too few: readers walk the records instead).
    processor : int
        84 Intel, 85 DEC, 86 MIPS (big-endian).
    n_points : int
        Points per frame.
    analog_per_frame : int
        Analog samples (all channels) per point frame.
    first_frame, last_frame : int
        1-based frame numbers, as stored.
    scale : float
        ``POINT:SCALE`` as the header holds it: negative for float storage.
    data_block : int
        1-based block where the data start.
    frame_rate : float
        Point frames per second.
    file_size : int
        Bytes in the file.
    """

    parameter_block: int
    parameter_blocks: int
    processor: int
    n_points: int
    analog_per_frame: int
    first_frame: int
    last_frame: int
    scale: float
    data_block: int
    frame_rate: float
    file_size: int

    @property
    def byte_order(self) -> str:
        """``struct`` byte order of the file's integers."""
        return ">" if self.processor == 86 else "<"

    @property
    def n_frames(self) -> int:
        """Frames the header declares (``last − first + 1``)."""
        return self.last_frame - self.first_frame + 1

    @property
    def data_bytes(self) -> int:
        """Bytes of point and analog data the header declares."""
        word = 4 if self.scale < 0 else 2
        return self.n_frames * (4 * self.n_points + self.analog_per_frame) * word


_C3D_PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS"}


def _c3d_float(raw: bytes, processor: int) -> float:
    if processor == 86:
        return float(struct.unpack(">f", raw)[0])
    if processor == 85:  # DEC F-float: 16-bit halves swapped, exponent bias 2 higher
        return float(struct.unpack("<f", raw[2:4] + raw[0:2])[0]) / 4.0
    return float(struct.unpack("<f", raw)[0])


def read_c3d_header(path: str | Path) -> C3DHeader:
    """Read and check a C3D file's 512-byte header (and the processor byte after it).

    Parameters
    ----------
    path : str or Path
        The C3D file.

    Returns
    -------
    C3DHeader

    Raises
    ------
    ParseError
        On an empty or short file, a second byte other than 0x50, an unknown processor type,
        a frame range or data start that cannot be, or data declared beyond the end of the
        file.
    """
    path = Path(path)
    try:
        size = path.stat().st_size
        with path.open("rb") as handle:
            head = handle.read(512)
            parameter_block = head[0] if head else 0
            handle.seek(max(parameter_block - 1, 0) * 512)
            section_head = handle.read(4)
    except OSError as e:
        raise ParseError(f"Expected a readable file, got {e.strerror or e}", path) from e
    if size == 0:
        raise ParseError("Expected a C3D file, got an empty file", path)
    if len(head) < 512:
        raise ParseError(f"Expected a 512-byte C3D header, got {len(head)} bytes", path)
    if head[1] != 0x50:
        raise ParseError(f"Expected a C3D file (second byte 0x50), got 0x{head[1]:02x}", path)
    if parameter_block < 2 or len(section_head) < 4:
        raise ParseError(
            f"Expected a parameter section after the header, got block {parameter_block} of a "
            f"{size}-byte file (truncated file?)",
            path,
        )
    processor = section_head[3]
    if processor not in _C3D_PROCESSORS:
        raise ParseError(
            f"Expected processor type 84 (Intel), 85 (DEC) or 86 (MIPS), got {processor}", path
        )
    order = ">" if processor == 86 else "<"
    words = struct.unpack(f"{order}9H", head[2:20])
    n_points, analog, first, last = words[0], words[1], words[2], words[3]
    header = C3DHeader(
        parameter_block=parameter_block,
        parameter_blocks=section_head[2],
        processor=processor,
        n_points=n_points,
        analog_per_frame=analog,
        first_frame=first,
        last_frame=last,
        scale=_c3d_float(head[12:16], processor),
        data_block=words[7],
        frame_rate=_c3d_float(head[20:24], processor),
        file_size=size,
    )
    if header.n_frames < 0:
        raise ParseError(f"Expected a last frame from the first on, got {first} to {last}", path)
    if not math.isfinite(header.scale) or (header.scale == 0 and n_points):
        raise ParseError(f"Expected a non-zero POINT:SCALE, got {header.scale:g}", path)
    data_start = (header.data_block - 1) * 512
    if header.data_bytes and header.data_block <= parameter_block:
        raise ParseError(
            f"Expected the data to start after the parameters (block {parameter_block + 1} or "
            f"later), got block {header.data_block}",
            path,
        )
    if header.data_bytes and data_start + header.data_bytes > size:
        raise ParseError(
            f"Expected the {header.data_bytes} bytes of data the header declares "
            f"({header.n_frames} frames), got {max(size - data_start, 0)} (truncated file?)",
            path,
        )
    return header


def check_c3d_header(header: C3DHeader, name: str, limits: ReadLimits) -> None:
    """Refuse a C3D whose header declares more than ``limits``, before it is parsed.

    Raises
    ------
    TooLargeError
        Points over ``max_markers``, frames × points over ``max_frame_points``, or data
        bytes over ``max_unpacked_bytes``.
    """
    check_marker_count(header.n_points, name, limits)
    if header.n_frames * header.n_points > limits.max_frame_points:
        raise TooLargeError(
            f"{name}: Expected at most {limits.max_frame_points} frames × points (setting "
            f"max_frame_points), got {header.n_frames} × {header.n_points}"
        )
    if header.data_bytes > limits.max_unpacked_bytes:
        raise TooLargeError(
            f"{name}: Expected at most {limits.max_unpacked_bytes} bytes of data (setting "
            f"max_unpacked_bytes), got {header.data_bytes}"
        )


def check_take_input(path: str | Path, kind: str, limits: ReadLimits) -> None:
    """Refuse a take file (or OpenPose folder) that exceeds ``limits``, before reading it.

    Parameters
    ----------
    path : str or Path
        The file or folder.
    kind : str
        Its format, as named by :func:`mocapqa.io.formats.detect_format`.
    limits : ReadLimits
        The limits.

    Raises
    ------
    TooLargeError
        Naming the file, the limit's setting and what was found.
    """
    path = Path(path)
    if kind in ("npy", "npz"):
        _check_arrays(path, kind, limits)
        return
    if kind == "c3d":
        check_c3d_header(read_c3d_header(path), path.name, limits)
        return
    for file in _files(path):
        if kind in TEXT_FORMATS:
            check_line_length(file, limits.max_line_bytes)
        if kind in JSON_FORMATS:
            check_json_depth(file, limits.max_json_depth)
    if kind == "bvh":
        _check_bvh_header(path, limits)
    check_frame_points(path, kind, limits)


def check_take_size(n_frames: int, n_points: int, name: str, limits: ReadLimits) -> None:
    """Refuse a read take larger than ``limits.max_frame_points`` (the check after parsing).

    Raises
    ------
    TooLargeError
    """
    if n_frames * n_points > limits.max_frame_points:
        raise TooLargeError(
            f"{name}: Expected at most {limits.max_frame_points} frames × points "
            f"(setting max_frame_points), got {n_frames} × {n_points}"
        )
