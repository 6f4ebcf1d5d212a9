"""Per-user limits on what uploads stage in ``incoming/``: imports at once, and bytes.

Every upload is received into ``incoming/`` (the file store's staging folder) before it becomes
a take, and an import also unpacks its archives there. A user's staged bytes are counted as
the requests' own sizes: the request guard holds each upload's or import's announced body
(``Content-Length``, else its body limit) from before the body is read until the request ends,
and an import adds each archive's declared unpacked total before the archive is unpacked (and
gives it back once the archive's members are stored). The bytes actually written stay within
these sizes, but for the copy of the one member being stored (at most an upload): the body
limit and the unpacked limits count what is written.

A request that would pass ``max_incoming_mb_per_user`` with what the user's other requests
hold gets :class:`~mocapqa.errors.RateLimitError` (429, ``Retry-After``); one that passes it
alone could never fit and gets :class:`~mocapqa.errors.TooLargeError` (413). An import beyond
``max_concurrent_imports_per_user`` in progress gets 429 too.
"""

from __future__ import annotations

import threading
from collections import Counter

from mocapqa.errors import RateLimitError, TooLargeError

__all__ = ["RETRY_AFTER_S", "StagingHold", "StagingQuota"]

RETRY_AFTER_S = 10
"""``Retry-After`` of a request refused for what the user's other requests hold."""


class StagingQuota:
    """Imports in progress and bytes held in ``incoming/``, per quota key (thread-safe).

    Parameters
    ----------
    max_imports : int
        Imports one key may have in progress (``max_concurrent_imports_per_user``).
    max_bytes : int
        Bytes one key's requests may hold (``max_incoming_mb_per_user``).
    """

    def __init__(self, max_imports: int, max_bytes: int) -> None:
        self.max_imports = max_imports
        self.max_bytes = max_bytes
        self._imports: Counter[str] = Counter()
        self._bytes: Counter[str] = Counter()
        self._lock = threading.Lock()

    def admit(self, key: str, nbytes: int, importing: bool = False) -> StagingHold:
        """Hold ``nbytes`` (and, ``importing``, an import's place) for one request of ``key``
        until the returned hold is closed.

        Raises
        ------
        TooLargeError
            ``nbytes`` alone pass the byte limit.
        RateLimitError
            With what the key's other requests hold, a limit would be passed.
        """
        with self._lock:
            self._check(key, 0, nbytes)
            if importing and self._imports[key] >= self.max_imports:
                raise RateLimitError(
                    f"Expected at most {self.max_imports} imports at once per user (setting "
                    f"max_concurrent_imports_per_user), got another while {self._imports[key]} "
                    "are in progress",
                    retry_after_s=RETRY_AFTER_S,
                )
            self._bytes[key] += nbytes
            if importing:
                self._imports[key] += 1
        return StagingHold(self, key, nbytes, importing)

    def held(self, key: str) -> tuple[int, int]:
        """``key``'s imports in progress and bytes held."""
        with self._lock:
            return self._imports[key], self._bytes[key]

    def reserve(self, key: str, mine: int, nbytes: int, what: str = "") -> None:
        """Hold ``nbytes`` more for a request of ``key`` that holds ``mine`` already (see
        :meth:`StagingHold.reserve`)."""
        with self._lock:
            self._check(key, mine, nbytes, what)
            self._bytes[key] += nbytes

    def release(self, key: str, nbytes: int, imports: int = 0) -> None:
        """Give back ``nbytes`` and ``imports`` places held by ``key``."""
        with self._lock:
            self._bytes[key] -= nbytes
            self._imports[key] -= imports
            for counts in (self._bytes, self._imports):
                if counts[key] <= 0:
                    del counts[key]  # forget idle keys

    def _check(self, key: str, mine: int, nbytes: int, what: str = "") -> None:
        """Refuse ``nbytes`` more for a request of ``key`` holding ``mine`` when they do not
        fit (the lock held)."""
        setting = f"Expected at most {self.max_bytes} bytes staged in incoming/ per user "
        setting += "(setting max_incoming_mb_per_user)"
        if mine + nbytes > self.max_bytes:
            raise TooLargeError(f"{setting}, got {mine + nbytes} for one request{what}")
        if self._bytes[key] + nbytes > self.max_bytes:
            raise RateLimitError(
                f"{setting}, got {nbytes} more{what} while {self._bytes[key]} held by requests "
                "in progress",
                retry_after_s=RETRY_AFTER_S,
            )


class StagingHold:
    """What one request holds of its key's allowance (see :meth:`StagingQuota.admit`)."""

    def __init__(self, quota: StagingQuota, key: str, nbytes: int, importing: bool) -> None:
        self._quota = quota
        self.key = key
        self.nbytes = nbytes
        self._importing = importing
        self._closed = False

    def reserve(self, nbytes: int, what: str = "") -> None:
        """Hold ``nbytes`` more (an archive's declared unpacked total, before unpacking it);
        ``what`` says what they are in a refusal's message.

        Raises
        ------
        TooLargeError
            This request's bytes with these pass the limit alone.
        RateLimitError
            With what the key's other requests hold, they pass it.
        """
        self._quota.reserve(self.key, self.nbytes, nbytes, what)
        self.nbytes += nbytes

    def release(self, nbytes: int) -> None:
        """Give back ``nbytes`` held by :meth:`reserve` (the archive's members are gone)."""
        nbytes = min(nbytes, self.nbytes)
        self.nbytes -= nbytes
        self._quota.release(self.key, nbytes)

    def close(self) -> None:
        """Give back everything this request holds (at its end; later calls do nothing)."""
        if not self._closed:
            self._closed = True
            self._quota.release(self.key, self.nbytes, 1 if self._importing else 0)
            self.nbytes = 0
