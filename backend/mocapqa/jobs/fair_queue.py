"""A queue of runs that serves clients in turn, so one client's flood does not starve others.

Each client has its own FIFO: the API queues a run under its user (``user:<id>``; the client
address for anonymous requests on a server without users), uploads, new runs and shoot imports
alike. :meth:`FairQueue.get` takes the next run of the client after the one served last, round
robin. A user with 50 queued runs and another with 1 see the second one's run start after at
most one of the first one's per worker, not after all 50.

With ``per_client`` set (the server's ``max_queued_runs_per_user``), at most that many runs of
one client are *in line* (waiting for a worker, or taken by one and not yet :meth:`done`); a
run put beyond it is *held*, in the order it came, and lines up when one of the client's runs
in line is done or removed. So a shoot import of 500 takes puts 20 runs in line, not 500: its
other runs wait as ids (their takes are stored, their runs recorded as queued).
"""

from __future__ import annotations

import threading
from collections import OrderedDict, deque

__all__ = ["FairQueue"]


class FairQueue:
    """Runs waiting for a worker, per client, taken round robin (thread-safe).

    Parameters
    ----------
    per_client : int, optional
        Most runs of one client in line (waiting or taken and not done); more are held until
        one is done. None: no limit.
    """

    def __init__(self, per_client: int | None = None) -> None:
        self.per_client = None if per_client is None else max(1, per_client)
        self._queues: OrderedDict[str, deque[str]] = OrderedDict()
        self._held: dict[str, OrderedDict[str, None]] = {}
        self._in_line: dict[str, int] = {}
        self._owner: dict[str, str] = {}
        self._condition = threading.Condition()
        self._closed = False

    def put(self, client: str, run_id: str) -> bool:
        """Queue ``run_id`` for ``client``: True when it is in line, False when it is held
        (``client`` has ``per_client`` runs in line)."""
        with self._condition:
            self._owner[run_id] = client
            if self.per_client is not None and self._in_line.get(client, 0) >= self.per_client:
                self._held.setdefault(client, OrderedDict())[run_id] = None
                return False
            self._line_up(client, run_id)
            return True

    def _line_up(self, client: str, run_id: str) -> None:
        self._queues.setdefault(client, deque()).append(run_id)
        self._in_line[client] = self._in_line.get(client, 0) + 1
        self._condition.notify()

    def _leave_line(self, client: str) -> None:
        """One of ``client``'s runs left the line: its first held run takes the place."""
        left = self._in_line.get(client, 0) - 1
        if left > 0:
            self._in_line[client] = left
        else:
            self._in_line.pop(client, None)
        held = self._held.get(client)
        if held:
            run_id = next(iter(held))
            del held[run_id]
            if not held:
                del self._held[client]
            self._line_up(client, run_id)

    def get(self) -> str | None:
        """The next run (blocking), or None once the queue is closed. The run stays in its
        client's line until :meth:`done`."""
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
            return run_id

    def done(self, run_id: str) -> None:
        """A run taken by :meth:`get` is finished: its place in line goes to the client's
        next held run. Nothing for a run already removed."""
        with self._condition:
            client = self._owner.pop(run_id, None)
            if client is not None:
                self._leave_line(client)

    def remove(self, run_id: str) -> bool:
        """Take a queued or held run out; False when it was neither (running or unknown)."""
        with self._condition:
            client = self._owner.get(run_id)
            if client is None:
                return False
            held = self._held.get(client)
            if held is not None and run_id in held:
                del held[run_id]
                if not held:
                    del self._held[client]
            else:
                runs = self._queues.get(client)
                if runs is None or run_id not in runs:
                    return False  # taken by a worker: done() frees its place
                runs.remove(run_id)
                if not runs:
                    del self._queues[client]
                self._leave_line(client)
            del self._owner[run_id]
            return True

    def waiting(self, client: str) -> int:
        """Runs of ``client`` waiting for a worker (in line, not taken)."""
        with self._condition:
            return len(self._queues.get(client, ()))

    def in_line(self, client: str) -> int:
        """Runs of ``client`` in line: waiting for a worker or taken and not done (at most
        ``per_client``)."""
        with self._condition:
            return self._in_line.get(client, 0)

    def held(self, client: str) -> int:
        """Runs of ``client`` held back until its runs in line are done."""
        with self._condition:
            return len(self._held.get(client, ()))

    def close(self) -> None:
        """Wake every waiting :meth:`get` with None; queued runs stay queued in the database."""
        with self._condition:
            self._closed = True
            self._condition.notify_all()
