"""The dashboard's page: ``frontend/index.html`` with its module graph's preloads filled in.

A browser finds a module's imports only once the module has arrived, so a graph several imports
deep costs one round trip per level before ``app.js`` runs (about 0.4 s for the take view on a
loaded 2-core machine). The server reads the graph of ``frontend/`` once, when the app is
built, and writes into the page:

* ``{{MODULE_PRELOADS}}``: a ``<link rel="modulepreload">`` for every module the page's own
  module scripts import, directly or not (static ``import``/``export ... from`` only), so they
  are all requested at once;
* ``{{ON_DEMAND_MODULES}}``: for each module loaded on demand (``import("./x.js")``: each
  view, the 3D views), a ``<meta name="modules-of" data-module="URL" content="...">`` listing
  it and every module it may load, static or on demand, not preloaded already; ``app.js``
  preloads a view's list when it opens the view, and ``prefetch.js`` the take view's as the
  page starts on a take, so a view's modules also arrive at once. The take list loads neither
  the take view's modules nor three.js.

Plotly is not a module (``plotly.js`` adds a classic ``<script>``), so it stays on demand.
Nothing here is a hand-kept list: a module added to the graph is preloaded from the next start.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from pathlib import Path
from posixpath import dirname, normpath
from typing import NamedTuple

__all__ = [
    "STATIC_URL",
    "IndexPage",
    "ModuleImports",
    "index_page",
    "largest_first",
    "module_graph",
    "module_imports",
    "reachable",
    "static_closure",
]

STATIC_URL = "/static/"
"""Where the server mounts ``frontend/`` (``app.mount("/static", ...)``)."""

_STATIC_IMPORT = re.compile(
    r"""(?:^|[;}])[ \t]*(?:import|export)[ \t]*(?:[\w$*{}, \t\n]*?from[ \t]*)?["']([^"'\n]+)["']""",
    re.MULTILINE,
)
"""``import x from "./a.js"``, ``import "./a.js"``, ``export { x } from "./a.js"``, also
minified (``import{a as b}from"./a.js"``), at a statement's start: a line's start or after
``;`` or ``}`` (so a ``//`` comment that mentions an import is not one)."""
_DYNAMIC_IMPORT = re.compile(r"""\bimport\(\s*["']([^"'\n]+)["']\s*\)""")
"""``import("./a.js")`` with a literal address (a template literal is not followed)."""
_MODULE_SCRIPT = re.compile(r"""<script type="module"(?: [\w-]+(?:="[^"]*")?)*? src="([^"?]+)""")
"""The page's own module scripts (``<script type="module" ... src="...">``)."""


class ModuleImports(NamedTuple):
    """The addresses one module imports, resolved against the module's own address."""

    static: list[str]
    """Modules imported with ``import``/``export ... from`` (needed before the module runs)."""
    dynamic: list[str]
    """Modules imported with ``import("...")`` (loaded when that code runs)."""


def _resolve(specifier: str, importer: str) -> str | None:
    """An import's address as the browser resolves it, or None for a bare name or a full URL."""
    if specifier.startswith("/"):
        return normpath(specifier)
    if specifier.startswith(("./", "../")):
        return normpath(f"{dirname(importer)}/{specifier}")
    return None


def _unique(addresses: Iterable[str | None]) -> list[str]:
    return list(dict.fromkeys(a for a in addresses if a is not None))


def module_imports(text: str, address: str) -> ModuleImports:
    """The modules a JavaScript module's source imports.

    Parameters
    ----------
    text : str
        The module's source (plain or minified).
    address : str
        The module's own URL path (``/static/js/take.js``), against which ``./`` and ``../``
        imports resolve.

    Returns
    -------
    ModuleImports
        Static and dynamic imports as URL paths, each once, in source order; bare names
        (``import "three"``) and full URLs are left out.
    """
    return ModuleImports(
        _unique(_resolve(m, address) for m in _STATIC_IMPORT.findall(text)),
        _unique(_resolve(m, address) for m in _DYNAMIC_IMPORT.findall(text)),
    )


def _file_of(root: Path, address: str) -> Path | None:
    """The file under ``root`` served at ``address`` (below ``STATIC_URL``), if there is one."""
    if not address.startswith(STATIC_URL):
        return None
    path = root / address.removeprefix(STATIC_URL)
    return path if path.is_file() else None


def module_graph(root: Path, entries: Iterable[str]) -> dict[str, ModuleImports]:
    """Every module reachable from ``entries`` by static or dynamic imports, read from disk.

    Parameters
    ----------
    root : Path
        The folder served at ``STATIC_URL`` (``frontend/``).
    entries : iterable of str
        URL paths of the modules to start from.

    Returns
    -------
    dict of str to ModuleImports
        Each module found (address → its imports), in the order found. An address with no
        file under ``root`` (three.js before ``make js-deps``, say) is left out.
    """
    graph: dict[str, ModuleImports] = {}
    todo = list(entries)
    while todo:
        address = todo.pop(0)
        path = _file_of(root, address)
        if address in graph or path is None:
            continue
        graph[address] = module_imports(path.read_text(encoding="utf-8"), address)
        todo.extend(graph[address].static + graph[address].dynamic)
    return graph


def static_closure(graph: dict[str, ModuleImports], entries: Iterable[str]) -> list[str]:
    """``entries`` and every module they import statically, directly or not, in depth-first
    order (a module before its imports); addresses missing from ``graph`` are left out."""
    seen: dict[str, None] = {}

    def visit(address: str) -> None:
        if address in seen or address not in graph:
            return
        seen[address] = None
        for imported in graph[address].static:
            visit(imported)

    for entry in entries:
        visit(entry)
    return list(seen)


def reachable(graph: dict[str, ModuleImports], entry: str) -> list[str]:
    """``entry`` and every module it may load, by static or dynamic imports, directly or not,
    in depth-first order; addresses missing from ``graph`` are left out."""
    seen: dict[str, None] = {}
    todo = [entry]
    while todo:
        address = todo.pop()
        if address in seen or address not in graph:
            continue
        seen[address] = None
        todo.extend(reversed(graph[address].static + graph[address].dynamic))
    return list(seen)


class IndexPage(NamedTuple):
    """The page as served and the modules it may load."""

    html: str
    """``index.html`` with its placeholders filled in."""
    modules: list[str]
    """URL paths of every module the page preloads or lists (its entries included)."""


def largest_first(root: Path, addresses: list[str], left_out: list[str]) -> list[str]:
    """``addresses`` but ``left_out``, the largest file first (ties in the given order).

    All of a view's modules are requested at once, and it runs only when the last has arrived:
    started first, the longest transfers and compilations (three.js's two files) overlap the
    many small ones instead of coming last.
    """
    sizes = {a: path.stat().st_size for a in addresses if (path := _file_of(root, a))}
    return sorted((a for a in addresses if a not in left_out), key=lambda a: -sizes.get(a, 0))


def index_page(root: Path, plotly_url: str) -> IndexPage:
    """``index.html`` as served: Plotly's address and the module graph's preloads.

    Parameters
    ----------
    root : Path
        The folder served at ``STATIC_URL``, holding ``index.html`` and ``js/``.
    plotly_url : str
        Where the server serves Plotly's bundle.

    Returns
    -------
    IndexPage
        The page, with ``{{PLOTLY_JS}}``, ``{{MODULE_PRELOADS}}`` and ``{{ON_DEMAND_MODULES}}``
        replaced, and the modules it names.
    """
    template = (root / "index.html").read_text(encoding="utf-8")
    entries = _MODULE_SCRIPT.findall(template)
    graph = module_graph(root, entries)
    preloaded = [a for a in static_closure(graph, entries) if a not in entries]
    links = [f'<link rel="modulepreload" href="{a}">' for a in preloaded]
    on_demand = _unique(d for imports in graph.values() for d in imports.dynamic if d in graph)
    metas = [
        f'<meta name="modules-of" data-module="{address}" content="{" ".join(modules)}">'
        for address in on_demand
        if (modules := largest_first(root, reachable(graph, address), preloaded + entries))
    ]
    html = (
        template.replace("{{PLOTLY_JS}}", plotly_url)
        .replace("{{MODULE_PRELOADS}}", "\n  ".join(links))
        .replace("{{ON_DEMAND_MODULES}}", "\n  ".join(metas))
    )
    return IndexPage(html, list(graph))
