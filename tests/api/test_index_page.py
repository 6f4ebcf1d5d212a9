"""The dashboard's page: the module graph read from ``frontend/`` and the preloads written into
``index.html`` (``mocapqa.api.index_page``)."""

from __future__ import annotations

import re
from pathlib import Path

from fastapi.testclient import TestClient

from mocapqa.api.app import create_app, frontend_dir
from mocapqa.api.index_page import (
    index_page,
    module_graph,
    module_imports,
    reachable,
    static_closure,
)
from mocapqa.config import Settings


def test_imports_plain_minified_and_on_demand() -> None:
    source = """// import { nothing } from "./commented.js";
import * as api from "./api.js";
import { a,
  b } from "../shared/b.js";
import "./side-effect.js";
export { h } from "./dom.js";
import * as THREE from "/static/vendor/three/three.module.min.js";
import x from "three";
const scene = import("./scene3d.js");
const page = await import(`./${name}.js`);
export const fromage = "from './nothing.js'";
"""
    found = module_imports(source, "/static/js/take.js")
    assert found.static == [
        "/static/js/api.js",
        "/static/shared/b.js",
        "/static/js/side-effect.js",
        "/static/js/dom.js",
        "/static/vendor/three/three.module.min.js",
    ]
    assert found.dynamic == ["/static/js/scene3d.js"]
    minified = (
        'x=1;import{Matrix3 as e,Vector2 as t}from"./three.core.min.js";export{a as b}from"./c.js"'
    )
    assert module_imports(minified, "/static/vendor/three/three.module.min.js").static == [
        "/static/vendor/three/three.core.min.js",
        "/static/vendor/three/c.js",
    ]


def write(root: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)


TREE = {
    "js/app.js": 'import { h } from "./dom.js";\nconst v = () => import("./view.js");\n',
    "js/dom.js": "export const h = 1;\n",
    "js/view.js": 'import { h } from "./dom.js";\nimport { c } from "./chart.js";\n'
    'const s = import("./scene.js");\n',
    "js/chart.js": 'import { h } from "./dom.js";\n',
    "js/scene.js": 'import * as T from "../vendor/lib.js";\nimport "./missing.js";\n',
    "vendor/lib.js": 'import{a}from"./core.js";/*' + "x" * 500 + "*/",
    "vendor/core.js": "export const a = 1;/*" + "x" * 300 + "*/",
}


def test_graph_closures_and_missing_files(tmp_path: Path) -> None:
    write(tmp_path, TREE)
    graph = module_graph(tmp_path, ["/static/js/app.js"])
    assert list(graph) == [
        "/static/js/app.js",
        "/static/js/dom.js",
        "/static/js/view.js",
        "/static/js/chart.js",
        "/static/js/scene.js",
        "/static/vendor/lib.js",
        "/static/vendor/core.js",
    ]  # ./missing.js has no file: left out
    assert static_closure(graph, ["/static/js/app.js"]) == [
        "/static/js/app.js",
        "/static/js/dom.js",
    ]
    assert reachable(graph, "/static/js/view.js") == [
        "/static/js/view.js",
        "/static/js/dom.js",
        "/static/js/chart.js",
        "/static/js/scene.js",
        "/static/vendor/lib.js",
        "/static/vendor/core.js",
    ]


def test_page_preloads_the_static_graph_and_lists_each_on_demand_module(tmp_path: Path) -> None:
    write(tmp_path, TREE)
    (tmp_path / "index.html").write_text(
        '<meta name="plotly-src" content="{{PLOTLY_JS}}">\n  {{ON_DEMAND_MODULES}}\n'
        '<script type="module" async src="/static/js/app.js"></script>\n  {{MODULE_PRELOADS}}\n'
    )
    page, modules = index_page(tmp_path, "/vendor/plotly-1.min.js")
    assert modules == list(module_graph(tmp_path, ["/static/js/app.js"]))
    assert "{{" not in page
    assert '<meta name="plotly-src" content="/vendor/plotly-1.min.js">' in page
    assert re.findall(r'rel="modulepreload" href="([^"]+)"', page) == ["/static/js/dom.js"]
    metas = dict(re.findall(r'name="modules-of" data-module="([^"]+)" content="([^"]+)"', page))
    # Each on-demand module's list, the largest file first.
    assert metas == {
        "/static/js/view.js": "/static/vendor/lib.js /static/vendor/core.js /static/js/view.js"
        " /static/js/scene.js /static/js/chart.js",
        "/static/js/scene.js": "/static/vendor/lib.js /static/vendor/core.js /static/js/scene.js",
    }


def imports_of(text: str) -> list[str]:
    """Relative imports of a module of the dashboard, read plainly (the test's own reading)."""
    return re.findall(r'(?:from\s*|import\(\s*)"(\.{1,2}/[\w./-]+\.js)"', text)


def take_view_modules(frontend: Path) -> set[str]:
    """take.js and every module it may load, followed through the files."""
    found: set[str] = set()
    todo = [frontend / "js" / "take.js"]
    while todo:
        path = todo.pop().resolve()
        address = "/static/" + path.relative_to(frontend.resolve()).as_posix()
        if address in found:
            continue
        found.add(address)
        todo += [path.parent / spec for spec in imports_of(path.read_text())]
        todo += [
            frontend / spec.removeprefix("/static/")
            for spec in re.findall(r'from "(/static/[\w./-]+\.js)"', path.read_text())
        ]
    return found


def test_served_page_preloads_every_module_of_the_take_view(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, allowed_hosts=["testserver"])
    with TestClient(create_app(settings)) as client:
        check_served_page(client)


def check_served_page(client: TestClient) -> None:
    page = client.get("/").text
    preloaded = set(re.findall(r'<link rel="modulepreload" href="([^"]+)">', page))
    take = re.search(r'name="modules-of" data-module="/static/js/take.js" content="([^"]+)"', page)
    assert take is not None
    on_take = set(take.group(1).split())
    expected = take_view_modules(frontend_dir())
    assert {"/static/js/take.js", "/static/js/scene3d.js", "/static/js/frames.js"} <= expected
    assert "/static/vendor/three/three.core.min.js" in expected
    # Every module the take view needs is preloaded by the page or listed for the take view.
    assert expected <= preloaded | on_take | {"/static/js/app.js"}
    # The router's own graph is preloaded for every view; the take view's is not (the take
    # list loads neither it nor three.js), and Plotly stays on demand (not a module).
    assert {"/static/js/api.js", "/static/js/dom.js", "/static/js/route.js"} <= preloaded
    assert not preloaded & {"/static/js/take.js", "/static/vendor/three/three.module.min.js"}
    assert "/vendor/plotly" not in take.group(1)
    assert "/vendor/plotly" not in str(preloaded)
    for address in preloaded | on_take:
        assert client.get(address).status_code == 200, address
