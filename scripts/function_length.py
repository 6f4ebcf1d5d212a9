"""Fail when a Python function in ``backend/`` runs over the length budget without a reason.

A function longer than ``LIMIT`` lines (from ``def`` to its last line, docstring included) must
say in its docstring why it stays whole (a paragraph starting "Kept whole because"), and at most
``MOST_KEPT_WHOLE`` may do so. Long functions hide their steps; the few that cannot be split
(a compiled kernel whose loop is one unit) say so where the reader looks first.

Usage: ``python scripts/function_length.py [FOLDER ...]`` (default ``backend``); exits 1 with
one line per offending function.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

LIMIT = 80
MOST_KEPT_WHOLE = 10
REASON = "Kept whole because"


def long_functions(folder: Path) -> list[tuple[str, int, bool]]:
    """Every function over ``LIMIT`` lines below ``folder``: (place, lines, gives a reason)."""
    found = []
    for path in sorted(folder.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = (node.end_lineno or node.lineno) - node.lineno + 1
                if lines > LIMIT:
                    reason = REASON in (ast.get_docstring(node) or "")
                    found.append((f"{path}:{node.lineno} {node.name}", lines, reason))
    return found


def main(folders: list[str]) -> int:
    """Print the offenders and return the exit status."""
    found = [row for folder in folders or ["backend"] for row in long_functions(Path(folder))]
    failures = [
        f"{place}: {lines} lines (over {LIMIT}) and no '{REASON} …' in its docstring"
        for place, lines, reason in found
        if not reason
    ]
    kept = [place for place, _, reason in found if reason]
    if len(kept) > MOST_KEPT_WHOLE:
        failures.append(
            f"{len(kept)} functions kept whole over {LIMIT} lines (at most {MOST_KEPT_WHOLE}): "
            + ", ".join(kept)
        )
    for line in failures:
        print(line)
    print(f"{len(found)} functions over {LIMIT} lines, {len(kept)} kept whole with a reason")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
