"""``run_watched`` samples a process's own memory apart from its children's (the batch client
apart from its Dask workers) and counts the CPU time of the whole tree."""

from __future__ import annotations

import sys

from mocapqa_bench.watch import run_watched

CHILD = """
import time
import numpy as np
block = np.ones(150 * 2**20 // 8)  # 150 MB, touched
t = time.process_time()
while time.process_time() - t < 0.3:
    pass
time.sleep(0.5)
"""
PARENT = f"""
import subprocess, sys, time
import numpy as np
block = np.ones(60 * 2**20 // 8)  # 60 MB, touched
subprocess.run([sys.executable, "-c", {CHILD!r}], check=True)
print("parent done", file=sys.stderr)
"""


def test_parent_and_child_memory_apart_and_cpu_of_the_tree() -> None:
    watched = run_watched([sys.executable, "-c", PARENT])
    assert watched.returncode == 0, watched.stderr
    assert "parent done" in watched.stderr
    assert 60 <= watched.peak_mb < 150 + 60, watched
    assert watched.children_peak_mb >= 150, watched
    assert watched.cpu_s >= 0.3, watched
    assert watched.wall_s >= 0.5, watched


def test_failure_keeps_its_code_and_message() -> None:
    watched = run_watched([sys.executable, "-c", "import sys; sys.exit('no such corpus')"])
    assert watched.returncode == 1
    assert "no such corpus" in watched.stderr
    assert watched.children_peak_mb == 0
