"""The one Dask execution layer of the server and the CLI.

With no address, :class:`Engine` starts a ``distributed.LocalCluster`` of worker *processes*
(one thread each, as many as the machine has cores unless told) the first time work is sent;
with ``MOCAPQA_DASK_SCHEDULER`` / ``--scheduler`` (``tcp://host:8786``) it connects to an
existing cluster instead. Work sent here runs in other processes: it reads its inputs itself
when the workers share the client's storage, and is sent them as bytes otherwise
(:meth:`Engine.shares_disk`, :mod:`mocapqa.jobs.sent_files`).

A task whose worker dies is retried on another worker; on the local cluster the scheduler's
``allowed-failures`` is 1, so a take that kills two workers fails with ``KilledWorker`` and
the batch goes on (an existing cluster keeps its own setting, Dask's default being 3). Its
``worker-saturation`` is 1.0, so no other take waits on a worker that dies.

A scheduler that cannot be reached, or is lost while working, is a :class:`ClusterError`
naming its address. How long the client tries (to connect, then to reconnect before it gives
up) is Dask's ``distributed.comm.timeouts.connect`` (30 s by default; the environment variable
``DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT`` sets it). Dask cancels every task in flight the
moment the connection drops, so a lost scheduler is known at once; a later :meth:`Engine.client`
connects afresh (to the restarted scheduler).
"""

from __future__ import annotations

import logging
import os
import threading
import time
from concurrent.futures import CancelledError
from pathlib import Path
from typing import Any

from mocapqa.errors import ClusterError

__all__ = [
    "ALLOWED_FAILURES",
    "SCHEDULER_LOST",
    "WORKER_CONFIG",
    "Engine",
    "default_workers",
    "worker_settings",
]

ALLOWED_FAILURES = 1
"""Worker deaths a task may cause on the local cluster before it is failed (Dask: 3)."""
SCHEDULER_LOST = "scheduler-connection-lost"
"""Dask's reason for the tasks it cancels when the client loses its scheduler."""
WORKER_CONFIG = "data/dask/mocapqa.yaml"
"""Dask settings for the workers (within the package): the local cluster's, and the image's
``/etc/dask/mocapqa.yaml`` for the compose file's workers."""
log = logging.getLogger(__name__)


def worker_settings() -> dict[str, Any]:
    """The nested Dask settings of :data:`WORKER_CONFIG`."""
    from importlib import resources

    import dask.config

    with resources.as_file(resources.files("mocapqa") / WORKER_CONFIG) as path:
        (loaded,) = dask.config.collect_yaml([str(path)])
    return dict(loaded)


def default_workers() -> int:
    """Worker processes of the local cluster: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


class Engine:
    """A lazily connected Dask client.

    Parameters
    ----------
    scheduler : str, optional
        Address of an existing scheduler (``tcp://host:8786``); None starts a local cluster.
    workers : int, optional
        Worker processes of the local cluster (default: :func:`default_workers`).
    """

    def __init__(self, scheduler: str | None = None, workers: int | None = None) -> None:
        self.scheduler = scheduler or None
        self.workers = workers if workers and workers > 0 else default_workers()
        self._client: Any = None
        self._cluster: Any = None
        self._lock = threading.Lock()

    @property
    def started(self) -> bool:
        """Whether the client is connected."""
        return self._client is not None

    @property
    def address(self) -> str:
        """The scheduler's address (the local cluster's once started), for messages."""
        if self.scheduler:
            return self.scheduler
        if self._cluster is not None:
            return str(self._cluster.scheduler_address)
        return "the local cluster"

    def client(self) -> Any:
        """The ``distributed.Client``, connecting (or starting the local cluster) on first use
        and again after the connection was lost.

        Raises
        ------
        ClusterError
            When the scheduler cannot be reached within Dask's connect timeout.
        """
        with self._lock:
            if self._client is not None and self._client.status in ("closing", "closed"):
                log.warning("the Dask client of %s was closed; connecting again", self.address)
                self._drop_client()
            if self._client is None:
                import dask
                from distributed import Client, LocalCluster

                if self.scheduler:
                    log.info("connecting to the Dask scheduler at %s", self.scheduler)
                    timeout = dask.config.get("distributed.comm.timeouts.connect")
                    try:
                        self._client = Client(self.scheduler)  # type: ignore[no-untyped-call]
                    except (OSError, TimeoutError) as e:
                        raise ClusterError(
                            f"Expected a Dask scheduler at {self.scheduler}, could not reach "
                            f"it within {timeout} ({e})"
                        ) from e
                else:
                    dask.config.set(
                        {
                            "distributed.scheduler.allowed-failures": ALLOWED_FAILURES,
                            # One task per worker thread at a time: a take queued behind a
                            # crashing one on the same worker would be counted among the
                            # tasks its death killed (Dask's default 1.1 sends two).
                            "distributed.scheduler.worker-saturation": 1.0,
                            "distributed.worker.daemon": False,
                        }
                    )
                    dask.config.update(dask.config.config, worker_settings(), priority="new")
                    self._cluster = LocalCluster(  # type: ignore[no-untyped-call]
                        n_workers=self.workers,
                        threads_per_worker=1,
                        processes=True,
                        dashboard_address=None,
                        silence_logs=logging.WARNING,
                    )
                    self._client = Client(self._cluster)  # type: ignore[no-untyped-call]
            return self._client

    def lost(self, error: BaseException) -> ClusterError | None:
        """The :class:`ClusterError` to raise when ``error`` (a task's result) means the
        scheduler was lost: Dask cancelled the task for that, or the client is no longer
        running; None for any other error (a killed worker, a bug in one take)."""
        reason = getattr(error, "reason", None)
        status = getattr(self._client, "status", None)
        if reason == SCHEDULER_LOST or status in ("connecting", "closing", "closed"):
            return self.lost_connection(error)
        return None

    def lost_connection(self, error: BaseException) -> ClusterError:
        """The :class:`ClusterError` that says the scheduler was lost, naming its address and
        the ``error`` that showed it."""
        return ClusterError(
            f"Lost the connection to the Dask scheduler at {self.address} "
            f"({type(error).__name__}: {error})"
        )

    def lost_after_settling(self, error: BaseException, wait_s: float = 5.0) -> ClusterError | None:
        """:meth:`lost`, for a task that failed while the client may not yet know its scheduler
        is gone: a cancellation (a batch cancels nothing itself) or a closed connection gives
        the client up to ``wait_s`` seconds to notice before the error is blamed on the take;
        a cancellation is a lost scheduler either way.

        Parameters
        ----------
        error : BaseException
            What the task's result raised.
        wait_s : float
            Longest wait for the client to leave its running state (seconds).
        """
        cancelled = isinstance(error, CancelledError)
        if not (cancelled or type(error).__name__ == "CommClosedError"):
            return self.lost(error)
        deadline = time.monotonic() + wait_s
        while getattr(self._client, "status", None) == "running" and time.monotonic() < deadline:
            time.sleep(0.05)
        found = self.lost(error)
        if found is None and cancelled:
            return self.lost_connection(error)
        return found

    def shares_disk(self, sample: Path, folder: Path | None) -> bool:
        """Whether the workers read the client's files and write the data folder themselves.

        The local cluster does, by construction; an existing cluster is asked (every connected
        worker must read ``sample`` as the client does and, with a ``folder``, see and may
        write in it: :func:`mocapqa.jobs.sent_files.workers_share`). When it does not, work is
        sent as bytes and its files come back.

        Parameters
        ----------
        sample : Path
            One input file the client reads.
        folder : Path, optional
            The data folder the work writes to.
        """
        if not self.scheduler:
            return True
        from mocapqa.jobs.sent_files import workers_share

        shared = workers_share(self.client(), sample, folder)
        log.info(
            "the workers of %s %s the client's files",
            self.address,
            "share" if shared else "do not share",
        )
        return shared

    def n_workers(self) -> int:
        """Workers connected now."""
        return len(self.client().scheduler_info(n_workers=-1)["workers"])

    def _drop_client(self) -> None:
        client, self._client = self._client, None
        try:
            if client.status == "running":
                client.close()
            else:  # lost: stop its reconnect loop, do not wait on the gone scheduler
                client.close(timeout=5)
        except Exception as e:  # a client already closing may refuse; it is dropped anyway
            log.debug("closing the lost Dask client: %s", e)

    def close(self) -> None:
        """Disconnect, and stop the local cluster if this engine started it."""
        with self._lock:
            if self._client is not None:
                self._drop_client()
            if self._cluster is not None:
                try:
                    self._cluster.close()
                finally:
                    self._cluster = None

    def __enter__(self) -> Engine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
