"""A run's folder and a take's reading record: the file names, and writing and reading them.

Layout under the data folder (the folders are :class:`~mocapqa.store.files.FileStore`'s)::

    takes/<take_id>/<file name>       the take as received
    takes/<take_id>/.reading.json     how it was read (READING_FILE)
    runs/<run_id>/report.json         the report: summary, steps, findings, series, downloads
    runs/<run_id>/points.npz          raw and corrected points (float32, NaN = missing) and
                                      the other arrays of POINT_ARRAYS the run has
    runs/<run_id>/corrected.bvh       a motion run's corrected take
    runs/<run_id>/filtered.csv|.trc   a keypoint run's filtered keypoints
    runs/<run_id>/corrected.c3d       a C3D marker run's repaired take
    runs/<run_id>/thumbnail.png       the rendered thumbnail (:mod:`mocapqa.jobs.rendered`)
    runs/<run_id>/report.html         the HTML report, built on its first download
    runs/<run_id>/prior.json          the reviewer prior a twist run used, when it had one
                                      (:class:`~mocapqa.twist.reviewer_prior.ReviewerPrior`)

Conventions
-----------
* No other module names these files: they ask :class:`RunFolder` for a path, or call the
  readers and writers here.
* Every file is written atomically (:meth:`FileStore.write_bytes`, or a temporary name and a
  rename), and a run's files are all written before the run is marked done.
* The analysis stack is imported inside the writers, not by this module: the batch client
  imports it to name the files it is sent back.
"""

from __future__ import annotations

import functools
import io
import json
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from mocapqa.errors import InputError, MocapQAError, NotFoundError
from mocapqa.pipeline.loading import ReadOptions
from mocapqa.store.files import FileStore

if TYPE_CHECKING:
    from mocapqa.markers.repair import MarkerRepair
    from mocapqa.pipeline.analyze import AnalysisResult
    from mocapqa.twist.reviewer_prior import ReviewerPrior

__all__ = [
    "CORRECTED_BVH",
    "CORRECTED_C3D",
    "DOWNLOAD_FILES",
    "FILTERED_CSV",
    "FILTERED_TRC",
    "POINTS_NPZ",
    "POINT_ARRAYS",
    "PRIOR_JSON",
    "READING_FILE",
    "REPORT_HTML",
    "REPORT_JSON",
    "THUMBNAIL_PNG",
    "RunFolder",
    "StoredRun",
    "joint_parents_of",
    "joints_of",
    "load_points",
    "load_report",
    "read_options_of",
    "read_run",
    "reading_of",
    "relative_folder",
    "run_summary",
    "twist_items_of",
    "write_corrected_c3d",
    "write_outputs",
    "write_reading",
]

log = logging.getLogger(__name__)

READING_FILE = ".reading.json"
"""A take's record of how it was read, in its folder (no stored take name starts with ".")."""
REPORT_JSON = "report.json"
"""A run's report."""
POINTS_NPZ = "points.npz"
"""A run's point arrays (:data:`POINT_ARRAYS`)."""
CORRECTED_BVH = "corrected.bvh"
"""A motion run's corrected take."""
CORRECTED_C3D = "corrected.c3d"
"""A C3D marker run's take with its swaps repaired and gaps filled."""
FILTERED_CSV = "filtered.csv"
"""A keypoint run's filtered keypoints as CSV (with the CSV's sidecar beside it)."""
FILTERED_TRC = "filtered.trc"
"""A keypoint run's filtered keypoints as TRC."""
THUMBNAIL_PNG = "thumbnail.png"
"""A run's rendered thumbnail."""
REPORT_HTML = "report.html"
"""A run's HTML report."""
PRIOR_JSON = "prior.json"
"""The reviewer prior a twist run used (its ``to_json``), so the run can be made again."""
DOWNLOAD_FILES = {
    "bvh": CORRECTED_BVH,
    "csv": FILTERED_CSV,
    "trc": FILTERED_TRC,
    "c3d": CORRECTED_C3D,
    "report": REPORT_JSON,
}
"""The file of each download kind a report lists in ``downloads``."""
POINT_ARRAYS = (
    "raw",
    "corrected",
    "raw_rotations",
    "corrected_rotations",
    "confidence",
    "bridged",
    "filled",
)
"""The arrays of :data:`POINTS_NPZ`, in this order (those a run has): ``raw`` and
``corrected`` (F, P, 3) positions, file units; motion takes' ``raw_rotations`` and
``corrected_rotations`` (F, P, 4) world unit quaternions, scalar-last; keypoint takes'
``confidence`` (F, P) and, when filtered, ``bridged`` (F, P); checked marker takes'
``filled`` (F, P)."""


@dataclass(frozen=True)
class RunFolder:
    """The paths of one run's files.

    Parameters
    ----------
    path : Path
        The run's folder (``runs/<run_id>``).
    """

    path: Path

    @classmethod
    def of(cls, files: FileStore, run_id: str) -> RunFolder:
        """The folder of ``run_id`` in ``files``."""
        return cls(files.run_dir(run_id))

    @property
    def report(self) -> Path:
        """:data:`REPORT_JSON`."""
        return self.path / REPORT_JSON

    @property
    def points(self) -> Path:
        """:data:`POINTS_NPZ`."""
        return self.path / POINTS_NPZ

    @property
    def thumbnail(self) -> Path:
        """:data:`THUMBNAIL_PNG`."""
        return self.path / THUMBNAIL_PNG

    @property
    def report_html(self) -> Path:
        """:data:`REPORT_HTML`."""
        return self.path / REPORT_HTML

    @property
    def prior(self) -> Path:
        """:data:`PRIOR_JSON`."""
        return self.path / PRIOR_JSON

    def download(self, kind: str) -> Path:
        """The file of a download kind (:data:`DOWNLOAD_FILES`)."""
        return self.path / DOWNLOAD_FILES[kind]


def relative_folder(files: FileStore, folder: Path) -> str:
    """``folder`` relative to the data folder, as POSIX (``runs/<run_id>``), for sending."""
    return folder.relative_to(files.root).as_posix()


@dataclass(frozen=True)
class StoredRun:
    """A finished run as stored: its report and its raw and corrected positions.

    Attributes
    ----------
    folder : Path
        The run's folder.
    report : dict
        The report JSON.
    raw, corrected : ndarray, shape (F, P, 3)
        Positions in file units, float64, NaN where missing.
    """

    folder: Path
    report: dict[str, Any]
    raw: np.ndarray
    corrected: np.ndarray


def load_report(source: Path | bytes) -> dict[str, Any]:
    """A run's report from its file (or the file's bytes).

    Raises
    ------
    OSError, ValueError
        When it is missing or not JSON.
    """
    data = source if isinstance(source, bytes) else source.read_bytes()
    report: dict[str, Any] = json.loads(data)
    return report


def load_points(source: Path | bytes, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Arrays ``names`` of a run's points (its file, or the file's bytes), as stored
    (:data:`POINT_ARRAYS`).

    Raises
    ------
    OSError, ValueError, KeyError
        When the file is missing, unreadable or lacks an array.
    """
    opened = io.BytesIO(source) if isinstance(source, bytes) else source
    with np.load(opened) as data:
        return {name: data[name] for name in names}


def read_run(folder: Path) -> StoredRun:
    """A stored run's report and positions (``report.json`` and ``points.npz``).

    Raises
    ------
    NotFoundError
        When either file is missing.
    InputError
        When they cannot be read.
    """
    run = RunFolder(folder)
    try:
        report = load_report(run.report)
        points = load_points(run.points, ("raw", "corrected"))
    except FileNotFoundError as e:
        raise NotFoundError(
            f"Expected a run folder with {REPORT_JSON} and {POINTS_NPZ}, got {e.filename}"
        ) from e
    except (OSError, ValueError, KeyError) as e:
        raise InputError(f"{folder}: Expected a readable run report and points, got {e}") from e
    raw, corrected = (np.asarray(points[n], dtype=np.float64) for n in ("raw", "corrected"))
    return StoredRun(folder, report, raw, corrected)


def write_reading(files: FileStore, take_id: str, facts: dict[str, Any]) -> None:
    """Record how a take was read (:func:`~mocapqa.pipeline.loading.reading_facts`)."""
    files.write_bytes(files.take_dir(take_id) / READING_FILE, json.dumps(facts).encode())


def reading_in(folder: Path) -> dict[str, Any] | None:
    """How the take in ``folder`` was read, if recorded."""
    try:
        data = json.loads((folder / READING_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def reading_of(files: FileStore, take_id: str) -> dict[str, Any] | None:
    """How a take was read (:func:`~mocapqa.pipeline.loading.reading_facts`), if recorded."""
    return reading_in(files.take_dir(take_id))


def read_options_of(folder: Path) -> ReadOptions:
    """The read options chosen at upload for the take in ``folder``, else the defaults."""
    try:
        return ReadOptions.from_json((reading_in(folder) or {}).get("read_options"))
    except (AttributeError, InputError):
        return ReadOptions()


def joints_of(files: FileStore, take_id: str) -> list[str] | None:
    """A BVH take's joint names as recorded when it was read (None for keypoint takes and
    takes stored before the names were recorded)."""
    joints = (reading_of(files, take_id) or {}).get("joints")
    return [str(j) for j in joints] if isinstance(joints, list) else None


def joint_parents_of(files: FileStore, take_id: str) -> list[int] | None:
    """A BVH take's parent index per joint as recorded when it was read (None for keypoint
    takes and takes stored before the hierarchy was recorded)."""
    parents = (reading_of(files, take_id) or {}).get("joint_parents")
    if not isinstance(parents, list) or not all(
        isinstance(p, int) and not isinstance(p, bool) for p in parents
    ):
        return None
    return [int(p) for p in parents]


def twist_items_of(files: FileStore, run_id: str) -> dict[int, tuple[str, float]]:
    """A finished run's twist intervals: id → (joint, calibrated probability as the run
    scored it), from its report's findings (empty for a run without twist findings or whose
    report cannot be read). A shoot's every run reads those of all its decided runs, so they
    are kept per report file (path, size and modification time) for the process's life."""
    path = RunFolder.of(files, run_id).report
    try:
        stat = path.stat()
    except OSError:
        return {}
    return dict(_twist_items(str(path), stat.st_size, stat.st_mtime_ns))


@functools.lru_cache(maxsize=4096)
def _twist_items(
    path: str, size: int, modified_ns: int
) -> tuple[tuple[int, tuple[str, float]], ...]:
    """:func:`twist_items_of` of one report file version (``size`` and ``modified_ns`` only
    key the cache)."""
    try:
        findings = load_report(Path(path)).get("findings") or []
    except (OSError, ValueError):
        return ()
    return tuple(
        (int(f["id"]), (str(f["joint"]), float(f.get("confidence") or 0.0)))
        for f in findings
        if isinstance(f, dict) and f.get("kind") == "twist" and "id" in f
    )


def run_summary(result: AnalysisResult) -> dict[str, Any]:
    """What a run stores as its summary: the report's summary, step states and QA summary."""
    from mocapqa.pipeline.summary import qa_summary

    return {
        **result.report["summary"],
        "steps": {k: v["state"] for k, v in result.report["steps"].items()},
        "qa": qa_summary(result),
    }


def write_corrected_c3d(path: Path, source: Path, repair: MarkerRepair | None) -> None:
    """Write a marker run's corrected take as C3D: the source's points with the repaired swaps
    and the applied fills (no filter), residuals and camera masks exchanged with the swaps,
    residual 0 and no cameras on every filled sample (C3D's mark of an interpolated sample);
    the source's analogs, force plates, events and other groups unchanged, or (a source ezc3d
    cannot open) the markers alone. ``repair`` is the run's (``AnalysisResult.markers``) or a
    reviewer's choice of it (:func:`mocapqa.jobs.accepted.decided_c3d`).

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


def _point_arrays(result: AnalysisResult) -> bytes:
    """The run's :data:`POINTS_NPZ` bytes."""
    arrays: dict[str, Any] = {
        "raw": result.raw_points.astype(np.float32),
        "corrected": result.corrected_points.astype(np.float32),
    }
    if result.raw_rotations is not None and result.corrected_rotations is not None:
        # Half precision (about 1e-3 per component) is finer than a drawn bone can show.
        arrays["raw_rotations"] = result.raw_rotations.astype(np.float16)
        arrays["corrected_rotations"] = result.corrected_rotations.astype(np.float16)
    if result.confidence is not None:
        arrays["confidence"] = result.confidence.astype(np.float16)
    if result.bridged is not None:
        arrays["bridged"] = result.bridged
    if result.markers is not None:
        arrays["filled"] = result.markers.filled
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


def _write_filtered(run: RunFolder, run_id: str, result: AnalysisResult) -> list[str]:
    """The filtered keypoints as CSV (with its sidecar) and TRC; returns the kinds written."""
    from mocapqa.io.keypoint_csv import csv_sidecar_path
    from mocapqa.pipeline.loading import write_keypoints_file

    if result.filtered_keypoints is None:
        return []
    kinds = []
    for kind in ("csv", "trc"):
        try:
            target = run.download(kind)
            temporary = target.with_name(f".{target.stem}.{run_id}{target.suffix}")
            write_keypoints_file(temporary, result.filtered_keypoints)
            temporary.replace(target)
            sidecar = csv_sidecar_path(temporary)  # the CSV's fps and unit
            if sidecar.is_file():
                sidecar.replace(csv_sidecar_path(target))
            kinds.append(kind)
        except MocapQAError as e:
            log.info("no %s output for run %s: %s", kind, run_id, e)
    return kinds


def _report_json(
    result: AnalysisResult, kinds: list[str], prior: ReviewerPrior | None = None
) -> bytes:
    """The report as stored: with its downloads, for keypoints the bones to draw and, for a
    run with a reviewer prior, the prior's ``summary`` (hash and counts) as
    ``reviewer_prior``."""
    from mocapqa.render.layouts import bones_for_keypoints

    points = result.report["points"]
    if result.report["kind"] == "keypoints":
        # The 3D views join the keypoints of a known layout (BODY_25B, MediaPipe 33, Pose2Sim);
        # markers of no known layout by the sticks of their inferred segments, when checked.
        layout = bones_for_keypoints(tuple(points["names"])).tolist()
        if layout or "bones" not in points:
            points = {**points, "bones": layout}
    report = {**result.report, "points": points, "downloads": kinds}
    if prior is not None:
        report["reviewer_prior"] = prior.summary()
    return json.dumps(report, allow_nan=False).encode()


def write_outputs(
    files: FileStore,
    run_id: str,
    result: AnalysisResult,
    source: Path | None = None,
    prior: ReviewerPrior | None = None,
) -> list[str]:
    """Write a run's files (report, points, corrected BVH or filtered keypoints; for a C3D
    marker take, ``corrected.c3d``: :func:`write_corrected_c3d`; the reviewer ``prior`` the
    run used, :data:`PRIOR_JSON`), the report last.

    Parameters
    ----------
    files : FileStore
    run_id : str
    result : AnalysisResult
    source : Path, optional
        The take's stored file (a C3D's is opened again for its residuals and other groups).
    prior : ReviewerPrior, optional
        The reviewer prior the analysis used (written whole, and summarised in the report).

    Returns
    -------
    list of str
        The download kinds written (``"report"``, ``"bvh"``, ``"csv"``, ``"trc"``, ``"c3d"``).
    """
    from mocapqa.io.bvh_write import format_bvh

    run = RunFolder.of(files, run_id)
    kinds = ["report"]
    files.write_bytes(run.points, _point_arrays(result))
    if result.corrected_motion is not None:
        files.write_bytes(run.download("bvh"), format_bvh(result.corrected_motion).encode())
        kinds.append("bvh")
    kinds += _write_filtered(run, run_id, result)
    if result.markers is not None and source is not None and source.suffix.lower() == ".c3d":
        try:
            write_corrected_c3d(run.download("c3d"), source, result.markers)
            kinds.append("c3d")
        except MocapQAError as e:
            log.info("no c3d output for run %s: %s", run_id, e)
    if prior is not None:
        files.write_bytes(run.prior, json.dumps(prior.to_json(), indent=2).encode())
    files.write_bytes(run.report, _report_json(result, kinds, prior))
    return kinds
