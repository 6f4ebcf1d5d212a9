"""A queue of runs that serves clients in turn, so one client's flood does not starve others.

Each client has its own FIFO: the API queues a run under its user (``user:<id>``; the client
address for anonymous requests on a server without users), uploads, new runs and shoot imports
alike. :meth:`FairQueue.get` takes the next run of the client after the one served last, round
robin. A user with 50 queued runs and another with 1 see the second one's run start after at
most one of the first one's per worker, not after all 50.
"""

from __future__ import annotations

import threading
from collections import OrderedDict, deque

__all__ = ["FairQueue"]


class FairQueue:
    """Runs waiting for a worker, per client, taken round robin (thread-safe)."""

    def __init__(self) -> None:
        self._queues: OrderedDict[str, deque[str]] = OrderedDict()
        self._owner: dict[str, str] = {}
        self._condition = threading.Condition()
        self._closed = False

    def put(self, client: str, run_id: str) -> None:
        """Queue ``run_id`` for ``client``."""
        with self._condition:
            self._queues.setdefault(client, deque()).append(run_id)
            self._owner[run_id] = client
            self._condition.notify()

    def get(self) -> str | None:
        """The next run (blocking), or None once the queue is closed."""
        with self._condition:
            while not self._closed and not self._queues:
                self._condition.wait()
            if self._closed:
                return None
            client, runs = next(iter(self._queues.items()))
            run_id = runs.popleft()
            del self._queues[client]
            if runs:  # back of the line: every other waiting client goes first
                self._queues[client] = runs
            self._owner.pop(run_id, None)
            return run_id

    def remove(self, run_id: str) -> bool:
        """Take a queued run out; False when it was not waiting."""
        with self._condition:
            client = self._owner.pop(run_id, None)
            if client is None:
                return False
            runs = self._queues[client]
            runs.remove(run_id)
            if not runs:
                del self._queues[client]
            return True

    def waiting(self, client: str) -> int:
        """Runs of ``client`` waiting."""
        with self._condition:
            return len(self._queues.get(client, ()))

    def close(self) -> None:
        """Wake every waiting :meth:`get` with None; queued runs stay queued in the database."""
        with self._condition:
            self._closed = True
            self._condition.notify_all()
