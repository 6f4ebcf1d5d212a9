"""A run's corrected take written in each format: a motion's corrected BVH, a keypoint take's
filtered CSV (with its sidecar) or TRC, a C3D marker take's repaired C3D.

The paths are :class:`~mocapqa.jobs.run_folder.RunFolder`'s (``corrected.bvh``,
``filtered.csv``, ``filtered.trc``, ``corrected.c3d``);
:func:`mocapqa.jobs.run_outputs.write_outputs` chooses which a run has, and a decided
download (:mod:`mocapqa.jobs.decided_markers`) writes a reviewer's choice of a C3D repair through
:func:`write_corrected_c3d`. Each file is written atomically. The readers and writers of the
formats are imported inside the functions: the batch client imports the run folder's names
without the analysis stack.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from mocapqa.errors import InputError
from mocapqa.store.files import FileStore

if TYPE_CHECKING:
    from mocapqa.core.keypoints import KeypointSequence
    from mocapqa.core.motion import Motion
    from mocapqa.markers.repair import MarkerRepair

__all__ = ["write_corrected_bvh", "write_corrected_c3d", "write_filtered_keypoints"]


def write_corrected_bvh(files: FileStore, path: Path, motion: Motion) -> None:
    """Write a motion run's corrected take as BVH (:func:`mocapqa.io.bvh_write.format_bvh`)."""
    from mocapqa.io.bvh_write import format_bvh

    files.write_bytes(path, format_bvh(motion).encode())


def write_filtered_keypoints(path: Path, keypoints: KeypointSequence, run_id: str) -> None:
    """Write a keypoint run's filtered keypoints in the format of ``path``'s suffix (``.csv``,
    with the CSV's sidecar of rate and unit beside it, or ``.trc``), through a temporary name
    that ``run_id`` keeps apart from another run's.

    Raises
    ------
    MocapQAError
        When the keypoints cannot be written in that format.
    """
    from mocapqa.io.keypoint_csv import csv_sidecar_path
    from mocapqa.pipeline.loading import write_keypoints_file

    temporary = path.with_name(f".{path.stem}.{run_id}{path.suffix}")
    write_keypoints_file(temporary, keypoints)
    temporary.replace(path)
    sidecar = csv_sidecar_path(temporary)  # the CSV's fps and unit
    if sidecar.is_file():
        sidecar.replace(csv_sidecar_path(path))


def write_corrected_c3d(path: Path, source: Path, repair: MarkerRepair | None) -> None:
    """Write a marker run's corrected take as C3D: the source's points with the repaired swaps
    and the applied fills (no filter), residuals and camera masks exchanged with the swaps,
    residual 0 and no cameras on every filled sample (C3D's mark of an interpolated sample);
    the source's analogs, force plates, events and other groups unchanged, or (a source ezc3d
    cannot open) the markers alone. ``repair`` is the run's (``AnalysisResult.markers``) or a
    reviewer's choice of it (:func:`mocapqa.jobs.decided_markers.decided_c3d`).

    Raises
    ------
    MocapQAError
        When the source cannot be read or the take written.
    """
    from dataclasses import replace

    from mocapqa.errors import UnsupportedFormatError
    from mocapqa.io.c3d import read_c3d, write_c3d

    if repair is None:
        raise InputError("Expected a run of the markers step to write a corrected C3D, got none")
    take = read_c3d(source)
    residuals = repair.carry(take.residuals, 0.0)
    masks = repair.carry(take.camera_masks, 0)
    points = replace(take.points, positions=repair.positions)
    corrected = replace(take, points=points, residuals=residuals, camera_masks=masks)
    try:
        write_c3d(path, corrected, source=source)
    except UnsupportedFormatError:
        write_c3d(path, corrected)
