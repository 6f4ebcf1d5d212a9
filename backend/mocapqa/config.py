"""Settings, built late: only ``create_app``, the CLI and the job runner call :func:`get_settings`.

Every setting has the ``MOCAPQA_`` environment prefix. Nothing here is read at import time, so
tests build their own :class:`Settings` (a temporary SQLite, a temporary folder) directly.

``MOCAPQA_DATA_DIR`` is where the server keeps its database and files. The real-data corpus the
tests and benchmarks read (``../shared/data``) is found by ``MOCAPQA_CORPUS_DIR`` (or
``MOCAPQA_DATA_DIR`` when that folder holds the corpus' ``MANIFEST.tsv``).
"""

from __future__ import annotations

from pathlib import Path

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict

__all__ = ["Settings", "get_settings"]


class Settings(BaseSettings):
    """Runtime settings of the server, CLI and jobs.

    Parameters
    ----------
    data_dir : Path
        Folder for the SQLite database and stored files.
    database_url : str, optional
        SQLAlchemy URL; defaults to SQLite at ``data_dir / "mocapqa.sqlite3"``.
    max_upload_mb : float
        Largest accepted upload, MB.
    corpus_dir : Path, optional
        The real-data corpus (for ``bench`` and ``limits build`` defaults).
    """

    model_config = SettingsConfigDict(env_prefix="MOCAPQA_", extra="ignore")

    data_dir: Path = Field(default_factory=lambda: Path.cwd() / "mocapqa-data")
    database_url: str | None = None
    max_upload_mb: float = 200.0
    corpus_dir: Path | None = None
    job_workers: int = 2

    @property
    def resolved_database_url(self) -> str:
        """The database URL in use (SQLite under ``data_dir`` unless set)."""
        if self.database_url:
            return self.database_url
        return f"sqlite:///{(self.data_dir / 'mocapqa.sqlite3').resolve()}"


def get_settings() -> Settings:
    """Build settings from the environment now (never cached at import)."""
    return Settings()
