"""The product and its benchmarks import without cycles: no module reaches a module that
reaches it back, counting imports inside functions and under ``TYPE_CHECKING``, as
import-linter's graph (grimp) does. (``jobs.intake → runner → take_task → runner`` and
``twist.detect → confidence → anatomy → detect`` were two.)"""

from __future__ import annotations

import grimp
import pytest


@pytest.mark.parametrize("package", ["mocapqa", "mocapqa_bench"])
def test_no_module_is_in_an_import_cycle(package: str) -> None:
    graph = grimp.build_graph("mocapqa", "mocapqa_bench", cache_dir=None)
    modules = sorted(m for m in graph.modules if m.startswith(f"{package}."))
    cycles = []
    for module in modules:
        for imported in sorted(graph.find_modules_directly_imported_by(module)):
            if imported.startswith(module + ".") or module.startswith(imported + "."):
                continue  # a package and its own modules
            back = graph.find_shortest_chain(importer=imported, imported=module)
            if back is not None:
                cycles.append((module, *back))
    assert cycles == []
