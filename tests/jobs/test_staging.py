"""The per-user staging allowance (issue 32): imports at once and bytes held in ``incoming/``,
429 for what other requests hold, 413 for what one request could never fit, all given back."""

from __future__ import annotations

import pytest

from mocapqa.errors import RateLimitError, TooLargeError
from mocapqa.jobs.staging import RETRY_AFTER_S, StagingQuota


def test_imports_past_the_limit_at_once_wait_for_one_to_end() -> None:
    quota = StagingQuota(max_imports=2, max_bytes=1000)
    first = quota.admit("user:1", 10, importing=True)
    quota.admit("user:1", 10, importing=True)
    quota.admit("user:1", 10)  # an upload is not an import
    quota.admit("user:2", 10, importing=True)  # another user's
    with pytest.raises(RateLimitError, match="setting max_concurrent_imports_per_user") as e:
        quota.admit("user:1", 10, importing=True)
    assert e.value.retry_after_s == RETRY_AFTER_S
    first.close()
    first.close()  # a second close gives nothing back twice
    quota.admit("user:1", 10, importing=True)
    assert quota.held("user:1") == (2, 30)


def test_bytes_past_the_allowance_are_429_beside_others_and_413_alone() -> None:
    """An archive's declared size is added to its request's hold before unpacking: refused
    with 429 when the user's other requests leave no room, 413 when the request alone would
    pass the allowance; refused bytes are not held, released ones are given back."""
    quota = StagingQuota(max_imports=2, max_bytes=1000)
    with pytest.raises(TooLargeError, match=r"setting max_incoming_mb_per_user\), got 1001"):
        quota.admit("user:1", 1001)
    other = quota.admit("user:1", 600)
    request = quota.admit("user:1", 100, importing=True)
    with pytest.raises(RateLimitError, match=r"got 400 more .* while 700 held"):
        request.reserve(400, " (400 unpacked from 'a.zip')")
    with pytest.raises(TooLargeError, match=r"got 1100 for one request \(1000 unpacked"):
        request.reserve(1000, " (1000 unpacked from 'b.zip')")
    assert quota.held("user:1") == (1, 700)
    other.close()
    request.reserve(400, " (400 unpacked from 'a.zip')")
    assert quota.held("user:1") == (1, 500)
    request.release(400)
    assert quota.held("user:1") == (1, 100)
    request.close()
    assert quota.held("user:1") == (0, 0)
