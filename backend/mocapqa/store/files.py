"""Files beside the database: uploaded takes and run outputs, written atomically.

Layout under the data folder::

    takes/<take_id>/<file name>        the upload, as received
    runs/<run_id>/report.json          the report
    runs/<run_id>/points.npz           raw and corrected point positions (float32, NaN = missing)
    runs/<run_id>/corrected.bvh        and filtered.csv / filtered.trc

Every file is written to a temporary name in the same folder and renamed, so a reader never
sees half a file and a crash leaves at most a ``.tmp`` file behind.
"""

from __future__ import annotations

import os
import shutil
import uuid
from pathlib import Path

from mocapqa.errors import NotFoundError

__all__ = ["FileStore"]


class FileStore:
    """Paths and atomic writes under one data folder.

    Parameters
    ----------
    root : Path
        The data folder (created when missing).
    """

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        for sub in ("takes", "runs", "incoming"):
            (self.root / sub).mkdir(parents=True, exist_ok=True)

    def incoming_path(self, suffix: str = "") -> Path:
        """A fresh path for an upload being received, ending in the client's ``suffix``."""
        return self.root / "incoming" / f"upload-{uuid.uuid4().hex[:12]}{suffix}"

    def take_dir(self, take_id: str) -> Path:
        """Folder of a take's files."""
        return self.root / "takes" / _checked(take_id)

    def run_dir(self, run_id: str) -> Path:
        """Folder of a run's outputs."""
        return self.root / "runs" / _checked(run_id)

    def adopt(self, source: Path, take_id: str, file_name: str) -> Path:
        """Move a received upload into its take folder; returns the new path."""
        folder = self.take_dir(take_id)
        folder.mkdir(parents=True, exist_ok=True)
        target = folder / file_name
        os.replace(source, target)
        return target

    def write_bytes(self, path: Path, data: bytes) -> None:
        """Write ``data`` to ``path`` through a temporary name and a rename."""
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
        with temporary.open("wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)

    def existing(self, path: Path, what: str) -> Path:
        """``path`` if it is a file, else :class:`NotFoundError` naming ``what``."""
        if not path.is_file():
            raise NotFoundError(f"Expected {what} to exist, got none")
        return path

    def remove_take(self, take_id: str, run_ids: list[str]) -> None:
        """Delete a take's files and its runs' outputs."""
        shutil.rmtree(self.take_dir(take_id), ignore_errors=True)
        self.remove_runs(run_ids)

    def remove_runs(self, run_ids: list[str]) -> None:
        """Delete these runs' outputs."""
        for run_id in run_ids:
            self.remove_run(run_id)

    def remove_run(self, run_id: str) -> None:
        """Delete a run's output folder (nothing when it has none)."""
        shutil.rmtree(self.run_dir(run_id), ignore_errors=True)

    def sweep_incoming(self) -> int:
        """Remove what a stopped server left in ``incoming/`` (partial uploads); returns the
        number of entries removed. Call before serving: every upload in progress is lost."""
        removed = 0
        for entry in (self.root / "incoming").iterdir():
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry, ignore_errors=True)
            else:
                entry.unlink(missing_ok=True)
            removed += 1
        return removed


def _checked(identifier: str) -> str:
    if len(identifier) != 32 or not all(c in "0123456789abcdef" for c in identifier):
        raise NotFoundError(f"Expected a 32-character hex id, got {identifier!r}")
    return identifier
