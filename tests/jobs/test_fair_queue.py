"""Runs are taken from clients in turn, so one client's flood does not starve another."""

from __future__ import annotations

import threading

from mocapqa.jobs.fair_queue import FairQueue


def test_clients_are_served_round_robin() -> None:
    queue = FairQueue()
    for i in range(5):
        queue.put("flood", f"f{i}")
    queue.put("other", "o0")
    queue.put("third", "t0")
    queue.put("other", "o1")
    order = [queue.get() for _ in range(8)]
    assert order == ["f0", "o0", "t0", "f1", "o1", "f2", "f3", "f4"]


def test_removed_runs_are_never_served_and_counts_follow() -> None:
    queue = FairQueue()
    for run in ("a", "b", "c"):
        queue.put("x", run)
    queue.put("y", "d")
    assert queue.waiting("x") == 3
    assert queue.remove("b")
    assert not queue.remove("b")
    assert queue.waiting("x") == 2
    assert [queue.get() for _ in range(3)] == ["a", "d", "c"]
    assert queue.waiting("x") == 0


def test_close_wakes_waiting_workers() -> None:
    queue = FairQueue()
    got: list[str | None] = []
    worker = threading.Thread(target=lambda: got.append(queue.get()))
    worker.start()
    queue.close()
    worker.join(timeout=60)
    assert got == [None]


def test_runs_beyond_the_per_client_limit_are_held_until_one_is_done() -> None:
    """A client's import puts ``per_client`` runs in line; the rest are held, in order, and
    line up one by one as its runs are done, without delaying another client."""
    queue = FairQueue(per_client=2)
    assert [queue.put("import", f"i{n}") for n in range(5)] == [True, True, False, False, False]
    assert queue.put("other", "o0")
    assert (queue.in_line("import"), queue.held("import")) == (2, 3)
    assert [queue.get() for _ in range(3)] == ["i0", "o0", "i1"]
    assert queue.waiting("import") == 0
    assert queue.in_line("import") == 2  # taken, not done
    queue.done("i0")
    assert (queue.in_line("import"), queue.held("import")) == (2, 2)
    assert queue.get() == "i2"
    queue.done("o0")
    assert queue.held("import") == 2  # another client's run frees no place of this one


def test_removing_a_held_or_queued_run_keeps_the_limit() -> None:
    queue = FairQueue(per_client=1)
    for run in ("a", "b", "c"):
        queue.put("x", run)
    assert queue.remove("b")  # held
    assert (queue.in_line("x"), queue.held("x")) == (1, 1)
    assert queue.remove("a")  # queued: the next held run takes its place
    assert (queue.in_line("x"), queue.held("x")) == (1, 0)
    assert queue.get() == "c"
    assert not queue.remove("c")  # running: done() frees its place
    queue.done("c")
    queue.done("c")
    assert queue.in_line("x") == 0
