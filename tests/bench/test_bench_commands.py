"""The ``mocapqa bench`` commands live in the ``mocapqa_bench`` package, beside the product: the
command group still lists and runs them, and the product's other commands never load them."""

from __future__ import annotations

import subprocess
import sys

from mocapqa.cli.app import bench_app
from mocapqa.cli.main import COMMAND_MODULES, import_command_module

BENCH_COMMANDS = ("api", "batch", "feet", "filters", "io", "limits", "markers", "render", "twist")


def test_every_bench_command_is_registered_from_the_bench_package() -> None:
    for command in BENCH_COMMANDS:
        for module in COMMAND_MODULES[f"bench {command}"]:
            import_command_module(module)
    modules = {(c.name, c.callback.__module__) for c in bench_app.registered_commands if c.callback}
    assert {name for name, _ in modules} == set(BENCH_COMMANDS)
    assert all(module.startswith("mocapqa_bench.cli.") for _, module in modules)


def test_bench_help_lists_every_command_and_info_loads_no_benchmark() -> None:
    listed = subprocess.run(
        [sys.executable, "-m", "mocapqa.cli.main", "bench", "--help"],
        check=True, capture_output=True, text=True,
    ).stdout  # fmt: skip
    for command in BENCH_COMMANDS:
        assert f" {command} " in listed, command
    probe = (
        "import sys; from mocapqa.cli.main import main; main(['info', '--help']); "
        "sys.stderr.write(' '.join(m for m in sys.modules if m.startswith('mocapqa_bench')))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=False
    ).stderr
    assert loaded == ""
