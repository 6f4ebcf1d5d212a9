"""Every public name (each module's ``__all__``) carries documentation.

Functions and classes need their own docstring (a dataclass' generated signature does not
count); constants and type aliases need a string literal right after the assignment or a
comment right above or beside it.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
from pathlib import Path
from types import ModuleType

import pytest

import mocapqa


def module_names() -> list[str]:
    names = [mocapqa.__name__]
    for info in pkgutil.walk_packages(mocapqa.__path__, prefix="mocapqa."):
        names.append(info.name)
    return sorted(names)


def own_docstring(obj: object) -> str | None:
    if inspect.isclass(obj):
        doc = obj.__dict__.get("__doc__")
        # dataclasses fill in "Name(field: type, ...)" when the class has no docstring.
        if isinstance(doc, str) and doc.startswith(f"{obj.__name__}("):
            return None
        return doc if isinstance(doc, str) else None
    doc = getattr(obj, "__doc__", None)
    return doc if isinstance(doc, str) else None


def documented_assignments(module: ModuleType) -> set[str]:
    """Module-level names assigned with a trailing string or an adjacent comment."""
    path = module.__file__
    if path is None:
        return set()
    source = Path(path).read_text(encoding="utf-8")
    lines = source.splitlines()
    tree = ast.parse(source)
    found: set[str] = set()
    body = tree.body
    for index, node in enumerate(body):
        targets: list[ast.expr] = []
        if isinstance(node, ast.Assign):
            targets = list(node.targets)
        elif isinstance(node, ast.AnnAssign):
            targets = [node.target]
        names = {t.id for t in targets if isinstance(t, ast.Name)}
        if not names:
            continue
        following = body[index + 1] if index + 1 < len(body) else None
        string_after = (
            isinstance(following, ast.Expr)
            and isinstance(following.value, ast.Constant)
            and isinstance(following.value.value, str)
        )
        above = lines[node.lineno - 2].strip() if node.lineno >= 2 else ""
        first = lines[node.lineno - 1]
        last = lines[(node.end_lineno or node.lineno) - 1]
        beside = "#" in first.split("=", 1)[-1] or "#" in last
        if string_after or above.startswith("#") or beside:
            found |= names
    return found


def imported_from(module: ModuleType) -> dict[str, str]:
    """Names a module takes from another module of the package (``from mocapqa.x import n``):
    name → that module. A re-exported constant is documented where it is defined."""
    path = module.__file__
    if path is None:
        return {}
    tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    return {
        alias.asname or alias.name: node.module
        for node in tree.body
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("mocapqa")
        for alias in node.names
    }


def constant_documented(module: ModuleType, name: str) -> bool:
    """Whether a module-level constant or alias is documented in ``module`` or, for a name it
    imports from another module of the package, in that module."""
    if name in documented_assignments(module):
        return True
    source = imported_from(module).get(name)
    return source is not None and constant_documented(importlib.import_module(source), name)


def undocumented(module: ModuleType) -> list[str]:
    missing = []
    for name in getattr(module, "__all__", ()):
        obj = inspect.unwrap(getattr(module, name))  # a functools.cache'd function is its own
        if inspect.isclass(obj) or inspect.isfunction(obj) or inspect.ismethod(obj):
            doc = own_docstring(obj)
            if not (doc and doc.strip()):
                missing.append(name)
        elif not constant_documented(module, name):
            missing.append(name)
    return missing


@pytest.mark.parametrize("name", module_names())
def test_every_public_name_has_a_docstring(name: str) -> None:
    module = importlib.import_module(name)
    assert (module.__doc__ or "").strip(), f"module {name} has no docstring"
    missing = undocumented(module)
    assert not missing, f"{name}: undocumented public names {missing}"


def test_the_checker_flags_what_it_should() -> None:
    from dataclasses import dataclass

    @dataclass
    class Bare:
        value: int

    @dataclass
    class Described:
        """Has words."""

        value: int

    def plain() -> None:
        pass

    assert own_docstring(Bare) is None
    assert own_docstring(Described) == "Has words."
    assert own_docstring(plain) is None
