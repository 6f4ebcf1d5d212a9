"""Settings, built late: only ``create_app``, the CLI and the job runner call :func:`get_settings`.

Every setting has the ``MOCAPQA_`` environment prefix. Nothing here is read at import time, so
tests build their own :class:`Settings` (a temporary SQLite, a temporary folder) directly.

``MOCAPQA_DATA_DIR`` is where the server keeps its database and files. The real-data corpus the
tests and benchmarks read (``../shared/data``) is found by ``MOCAPQA_CORPUS_DIR`` (or
``MOCAPQA_DATA_DIR`` when that folder holds the corpus' ``MANIFEST.tsv``).
"""

from __future__ import annotations

import ipaddress
from pathlib import Path
from typing import TYPE_CHECKING

from pydantic import Field, field_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

if TYPE_CHECKING:
    from mocapqa.io.guards import ReadLimits

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
    job_workers : int
        Analysis worker threads.
    trusted_proxies : list of str
        Addresses or networks (``10.0.0.5``, ``172.18.0.0/16``) of reverse proxies whose
        ``X-Forwarded-For`` and ``X-Forwarded-Proto`` headers are believed. None by default:
        the client is the address the connection comes from, whatever a header says, so a
        forged header cannot dodge the sign-in limit or write another address into the audit
        log (``docs/deploy.md``).
    server_threads : int
        Threads serving requests at once (the synchronous routes and dependencies); the
        database pool is sized for them and the job workers.

    The limits below are refused with their 4xx (413, 422 or 429) before their cost is paid;
    ``docs/api.md`` lists them with the reasoning behind each default.

    max_request_kb : float
        Largest body of any request other than an upload (JSON), KB.
    max_unpacked_mb : float
        Largest total size of the arrays inside an uploaded ``.npz``/``.npy``, MB.
    max_frame_points : int
        Largest frames × points (joints or keypoints) of a take.
    max_joints : int
        Largest number of joints in a BVH hierarchy.
    max_markers : int
        Largest number of markers (points) of a marker take (TRC, C3D).
    max_line_bytes : int
        Longest line of a text take, bytes.
    max_json_depth : int
        Deepest nesting of a JSON take.
    max_run_attempts : int
        Starts of a run interrupted by a server stop before it is failed with the reason.
    max_queued_runs_per_user : int
        Runs one user may have queued or running at once; more get 429 with ``Retry-After``.
        Anonymous requests (a server without users) count per client address.
    uploads_per_minute_per_user : int
        Uploads (and shoot imports) one user may start per minute; more get 429 with
        ``Retry-After``, before the body is read. Anonymous requests count per address.
    allowed_hosts : list of str
        Accepted ``Host`` header names (``*`` accepts any, ``*.example.org`` a domain's);
        IPv6 addresses with or without brackets. Loopback names by default.
    cors_origins : list of str
        Origins allowed to call the API from another site (CORS); none by default.
    stream_max_keypoints : int
        Largest ``n_keypoints`` of a live-filter stream.
    stream_max_frame_bytes : int
        Largest WebSocket message of a live-filter stream, bytes.
    stream_max_frames_per_s : float
        Most frames per second a live-filter stream may send (averaged over a second).
    dask_scheduler : str, optional
        ``tcp://host:8786`` of a Dask scheduler: the server's runs and ``mocapqa batch`` go
        to that cluster (see ``docs/batch.md``).
    archive_max_members : int
        Most members an uploaded archive may hold (checked before extracting).
    archive_max_unpacked_mb : float
        Most MB an uploaded archive may unpack to (declared sizes checked before extracting,
        written bytes while extracting).
    max_concurrent_imports_per_user : int
        Shoot imports one user may have in progress at once; more get 429 with
        ``Retry-After``, before the body is read. Anonymous requests count per address.
    max_incoming_mb_per_user : float
        Most MB one user's uploads and imports in progress may stage in ``incoming/`` (each
        request's announced body, and each archive's declared unpacked size before it is
        unpacked); more get 429 with ``Retry-After``, a request over it alone 413.
    """

    model_config = SettingsConfigDict(env_prefix="MOCAPQA_", extra="ignore")

    data_dir: Path = Field(default_factory=lambda: Path.cwd() / "mocapqa-data")
    database_url: str | None = None
    max_upload_mb: float = 200.0
    corpus_dir: Path | None = None
    job_workers: int = 2
    server_threads: int = Field(default=40, ge=1, le=1000)
    trusted_proxies: list[str] = Field(default_factory=list)

    @field_validator("trusted_proxies")
    @classmethod
    def _proxy_addresses(cls, value: list[str]) -> list[str]:
        for entry in value:
            try:
                ipaddress.ip_network(entry, strict=False)
            except ValueError:
                raise ValueError(
                    f"Expected trusted_proxies to hold IP addresses or networks, got {entry!r}"
                ) from None
        return value

    max_request_kb: float = 1024.0
    max_unpacked_mb: float = 200.0
    max_frame_points: int = 5_000_000
    max_joints: int = 500
    max_markers: int = 1000
    max_line_bytes: int = 1_000_000
    max_json_depth: int = 64
    max_run_attempts: int = 2
    max_queued_runs_per_user: int = 20
    uploads_per_minute_per_user: int = 30
    allowed_hosts: list[str] = Field(default_factory=lambda: ["localhost", "127.0.0.1", "::1"])
    cors_origins: list[str] = Field(default_factory=list)
    stream_max_keypoints: int = 1000
    stream_max_frame_bytes: int = 1_000_000
    stream_max_frames_per_s: float = 240.0

    @property
    def read_limits(self) -> ReadLimits:
        """The take readers' limits from these settings."""
        from mocapqa.io.guards import ReadLimits  # numpy: imported only where takes are read

        return ReadLimits(
            max_unpacked_bytes=int(self.max_unpacked_mb * 1_000_000),
            max_frame_points=self.max_frame_points,
            max_joints=self.max_joints,
            max_markers=self.max_markers,
            max_line_bytes=self.max_line_bytes,
            max_json_depth=self.max_json_depth,
        )

    dask_scheduler: str | None = None
    archive_max_members: int = 10_000
    archive_max_unpacked_mb: float = 2_000.0
    max_concurrent_imports_per_user: int = 2
    max_incoming_mb_per_user: float = 4_000.0

    @property
    def resolved_database_url(self) -> str:
        """The database URL in use (SQLite under ``data_dir`` unless set)."""
        if self.database_url:
            return self.database_url
        return f"sqlite:///{(self.data_dir / 'mocapqa.sqlite3').resolve()}"


def get_settings() -> Settings:
    """Build settings from the environment now (never cached at import)."""
    return Settings()
