"""Which task errors the batch blames on a lost scheduler rather than on the take."""

from __future__ import annotations

from concurrent.futures import CancelledError
from types import SimpleNamespace

from distributed.comm.core import CommClosedError

from mocapqa.jobs.engine import Engine


def _engine(status: str) -> Engine:
    engine = Engine("tcp://127.0.0.1:1")
    engine._client = SimpleNamespace(status=status)  # type: ignore[assignment]
    return engine


def test_a_cancellation_is_a_lost_scheduler_even_before_the_client_notices() -> None:
    lost = _engine("running").lost_after_settling(CancelledError("x"), wait_s=0.01)
    assert lost is not None
    assert "tcp://127.0.0.1:1" in str(lost)


def test_a_closed_connection_is_lost_once_the_client_leaves_running() -> None:
    assert _engine("connecting").lost_after_settling(CommClosedError("gone"), 0.01) is not None
    assert _engine("running").lost_after_settling(CommClosedError("gone"), 0.01) is None


def test_an_error_of_the_take_is_not_a_lost_scheduler() -> None:
    assert _engine("running").lost_after_settling(ValueError("bad take"), 0.01) is None
    assert _engine("running").lost_after_settling(OSError("disk full"), 0.01) is None
