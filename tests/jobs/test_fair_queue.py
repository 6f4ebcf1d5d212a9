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
