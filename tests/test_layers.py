"""The package's shape: the rooms follow the method's flow (mesh -> rounding -> vertex ->
surface -> layout -> export), a room imports only from the rooms before it, and no module
imports, even inside a function, a module that imports it back (directly or round a loop)."""

from __future__ import annotations

import ast
from pathlib import Path

import filletfold

ROOMS = ["mesh", "rounding", "vertex", "surface", "layout", "export"]
SRC = Path(filletfold.__file__).parent


def modules(root: Path = SRC) -> dict[str, Path]:
    out = {}
    for f in sorted(root.rglob("*.py")):
        parts = f.relative_to(root.parent).with_suffix("").parts
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = f
    return out


def import_graph(mods: dict[str, Path]) -> dict[str, set]:
    """Module -> the package modules it imports anywhere in its code (``from . import x``
    counts as importing ``x``)."""
    graph = {}
    for name, f in mods.items():
        package = name.split(".") if f.name == "__init__.py" else name.split(".")[:-1]
        found = set()
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.ImportFrom):
                base = package[: len(package) - node.level + 1] if node.level else []
                target = ".".join(base + ([node.module] if node.module else []))
                for alias in node.names:
                    sub = f"{target}.{alias.name}"
                    found.add(sub if sub in mods else target)
            elif isinstance(node, ast.Import):
                found.update(a.name for a in node.names)
        graph[name] = {t for t in found if t in mods and t != name}
    return graph


def cycles(graph: dict[str, set]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out, count = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = count[0]
        count[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def upward(graph: dict[str, set]) -> list[tuple[str, str]]:
    """Imports from a room into a room later in the flow."""

    def room(m):
        parts = m.split(".")
        return parts[1] if len(parts) > 2 and parts[1] in ROOMS else None

    return [
        (m, t)
        for m, ts in sorted(graph.items())
        for t in sorted(ts)
        if room(m) and room(t) and ROOMS.index(room(t)) > ROOMS.index(room(m))
    ]


def modules_only(graph: dict[str, set], mods: dict[str, Path]) -> dict[str, set]:
    """The graph between modules (a package's ``__init__`` re-exports its room: left out)."""
    packages = {m for m, f in mods.items() if f.name == "__init__.py"}
    return {m: ts - packages for m, ts in graph.items() if m not in packages}


def test_no_import_circle_and_no_room_imports_a_later_one():
    mods = modules()
    graph = modules_only(import_graph(mods), mods)
    assert len(graph) > 70 and graph["filletfold.vertex.batch"] >= {"filletfold.vertex.rows"}
    assert cycles(graph) == []
    assert upward(graph) == []


def test_the_checks_see_a_circle_and_an_upward_import(tmp_path):
    """Broken on purpose: a lazy import back into a module that imports it, and a surface
    module importing from export, are both found."""
    pkg = tmp_path / "filletfold"
    for room in ("surface", "export"):
        (pkg / room).mkdir(parents=True)
        (pkg / room / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "surface" / "a.py").write_text("from .b import x\n")
    (pkg / "surface" / "b.py").write_text("def x():\n    from .a import y\n")
    (pkg / "export" / "c.py").write_text("x = 1\n")
    (pkg / "surface" / "d.py").write_text("from ..export.c import x\n")
    mods = modules(pkg)
    graph = modules_only(import_graph(mods), mods)
    assert cycles(graph) == [["filletfold.surface.a", "filletfold.surface.b"]]
    assert upward(graph) == [("filletfold.surface.d", "filletfold.export.c")]
