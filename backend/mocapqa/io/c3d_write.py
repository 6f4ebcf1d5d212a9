"""Writing a C3D marker take through ezc3d, alone or over the file it was read from.

Conventions
-----------
* A missing sample is written as the standard says: zero coordinates with residual −1.
  Residuals are stored as multiples of ``|POINT:SCALE|``; a measured residual smaller than that
  step is written as one step, so 0 keeps meaning "filled".
* With ``source``, the source file is opened again and only its point data, labels,
  descriptions, units, rate and first frame are replaced: analogs, force plates, events and
  every other group are written as they were read.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.errors import InputError, ShapeError, UnsupportedFormatError
from mocapqa.io.atomic import atomic_path
from mocapqa.io.c3d_layout import check_for_ezc3d, inspect_c3d
from mocapqa.io.c3d_read import refusal_reason
from mocapqa.io.c3d_take import C3DEvent, MarkerTake

__all__ = ["write_c3d"]

_MAX_RESIDUAL_STEPS = 255


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
                raise InputError(f"Expected a take ezc3d can write, got {refusal_reason(e)}") from e
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
            f"Expected a source C3D that ezc3d reads, got {source.name} ({refusal_reason(e)})"
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
