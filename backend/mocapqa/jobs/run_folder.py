"""A run's folder: the names of its files and their paths (:class:`RunFolder`).

Layout under the data folder (the folders are :class:`~mocapqa.store.files.FileStore`'s)::

    takes/<take_id>/<file name>       the take as received
    takes/<take_id>/.reading.json     how it was read (:mod:`mocapqa.jobs.reading_record`)
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
* No other module names these files: they ask :class:`RunFolder` for a path. The run's files
  are written by :mod:`mocapqa.jobs.run_outputs` (its corrected take in each format by
  :mod:`mocapqa.jobs.corrected_takes`) and read back by :mod:`mocapqa.jobs.stored_run`; a
  take's reading record is :mod:`mocapqa.jobs.reading_record`'s.
* Every file is written atomically (:meth:`FileStore.write_bytes`, or a temporary name and a
  rename), and a run's files are all written before the run is marked done.
* This module imports no analysis stack: the batch client imports it to name the files it is
  sent back.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mocapqa.store.files import FileStore

__all__ = [
    "CORRECTED_BVH",
    "CORRECTED_C3D",
    "DOWNLOAD_FILES",
    "FILTERED_CSV",
    "FILTERED_TRC",
    "POINTS_NPZ",
    "POINT_ARRAYS",
    "PRIOR_JSON",
    "REPORT_HTML",
    "REPORT_JSON",
    "THUMBNAIL_PNG",
    "RunFolder",
    "relative_folder",
]

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
