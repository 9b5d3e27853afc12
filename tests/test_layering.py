"""Layering: the library never imports its front ends, and its rooms follow the method's flow.

Geometry lives in the library; the browser app (:mod:`filletfold.app`), the command line
(:mod:`filletfold.cli`) and the Hops server (:mod:`filletfold.hops`) only parse, call and
display. So no other module imports
``filletfold.app`` -- at the top or inside a function -- and in particular no writer under
:mod:`filletfold.export`. The rooms follow the flow (mesh -> rounding -> vertex -> surface ->
layout -> export): a room imports only from the rooms before it, and no module imports one
that imports it back, directly or round a loop. Read from the source with :mod:`ast`, so an
import that only runs on some path is seen too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import filletfold

ROOT = Path(filletfold.__file__).parent
#: The front ends: they may import the app (the Hops server takes the app's bind policy).
FRONT_ENDS = ("filletfold.app", "filletfold.cli", "filletfold.hops")


def module_name(path: Path, root: Path = ROOT) -> str:
    """``filletfold.export.png`` for ``.../filletfold/export/png.py`` (a package: its name)."""
    parts = ("filletfold", *path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path, root: Path = ROOT) -> set[str]:
    """Absolute names of every module ``path`` imports, anywhere in the file (relative imports
    resolved; ``from a import b`` counts as ``a`` and as ``a.b``, ``b`` may be a module)."""
    name = module_name(path, root)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join([*base, node.module] if node.module else base)
            else:
                target = node.module or ""
            out.add(target)
            out.update(f"{target}.{alias.name}" for alias in node.names)
    return out


def imports_app(path: Path) -> list[str]:
    return sorted(
        m
        for m in imported_modules(path)
        if m == "filletfold.app" or m.startswith("filletfold.app.")
    )


LIBRARY = sorted(p for p in ROOT.rglob("*.py") if not module_name(p).startswith(FRONT_ENDS))


def test_the_scan_sees_relative_and_local_imports():
    """Not vacuous: the command line's import of the app (inside a function, relative) is
    found, and every export module is among those scanned."""
    assert "filletfold.app.server" in imports_app(ROOT / "cli.py")
    png = imported_modules(ROOT / "export" / "png.py")
    assert {"filletfold.export.render", "filletfold.surface.pattern"} <= png
    scanned = {module_name(p) for p in LIBRARY}
    assert {"filletfold.export.png", "filletfold.export.mesh3d", "filletfold.export"} <= scanned


@pytest.mark.parametrize("path", LIBRARY, ids=module_name)
def test_no_library_module_imports_the_app(path):
    assert imports_app(path) == [], f"{module_name(path)} imports the browser app"


def test_no_export_module_imports_the_app():
    export = [p for p in LIBRARY if module_name(p).startswith("filletfold.export")]
    assert len(export) >= 15
    offenders = {module_name(p): imports_app(p) for p in export if imports_app(p)}
    assert offenders == {}


#: The rooms in the order of the method's flow.
ROOMS = ["mesh", "rounding", "vertex", "surface", "layout", "export"]


def import_graph(root: Path = ROOT) -> dict[str, set]:
    """Module -> the modules of the package under ``root`` that it imports anywhere
    (:func:`imported_modules`); a package's ``__init__``, which re-exports its room, is left
    out on both sides."""
    paths = {module_name(p, root): p for p in sorted(root.rglob("*.py")) if p.name != "__init__.py"}
    return {m: (imported_modules(p, root) & paths.keys()) - {m} for m, p in paths.items()}


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


def test_no_import_circle_and_no_room_imports_a_later_one():
    graph = import_graph()
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
    graph = import_graph(pkg)
    assert cycles(graph) == [["filletfold.surface.a", "filletfold.surface.b"]]
    assert upward(graph) == [("filletfold.surface.d", "filletfold.export.c")]


def parameter_counts(path: Path) -> dict[str, int]:
    """Function name -> how many parameters it takes (``self``/``cls`` not counted; ``*args``
    and ``**kwargs`` not counted), for every function and method in ``path``."""
    out = {}
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            a = node.args
            names = [x.arg for x in (*a.posonlyargs, *a.args, *a.kwonlyargs)]
            out[node.name] = len([n for n in names if n not in ("self", "cls")])
    return out


#: The pipeline's modules: the orchestrator, its stages, the parameters, and the state the apex
#: stage shares with the rescue and the sharp vertices.
PIPELINE = ["design.py", "pipeline.py", "parameters.py", "vertex/state.py", "vertex/rescue.py",
            "vertex/sharpen.py"]  # fmt: skip


#: The functions of more than 8 parameters the library keeps, and why: the public API (the
#: command line's options, the writers' formats, the solver's documented entry points) and
#: the numba kernel's compiled functions, which take arrays one by one.
MANY_PARAMETERS = {
    "cli.py:round_cmd": "the command's options",
    "check.py:certify": "public: the certificate's inputs and limits",
    "export/render.py:render": "public: the picture's options",
    "export/cutfiles.py:cut_files": "public: the cut files' options",
    "export/outputs.py:export_design": "public: Design.export's options",
    "vertex/solve.py:solve_apices": "public: the apex solver's entry point",
    "vertex/solve.py:_solve_round": "one round of solve_apices, with its arguments and work",
    "vertex/batch.py:interior_point_numpy": "public: the solver, twin of the kernel's",
    "vertex/batch_kernel.py:interior_point_numba": "public: the kernel, twin of numpy's",
    "vertex/batch_kernel.py:_status": "numba: arrays one by one",
    "vertex/batch_kernel.py:_kernel": "numba: arrays one by one",
    "vertex/batch_kernel.py:_start": "numba: arrays one by one",
    "vertex/batch_kernel.py:_step": "numba: arrays one by one",
    "vertex/batch_kernel.py:_settle": "numba: arrays one by one",
}


def test_no_function_takes_more_than_8_parameters_but_the_listed():
    """Outside the public API and the compiled kernel, what a function needs travels in a
    record (Parameters, Job, VertexState, a stage's result), not in a dozen arguments."""
    found = {
        f"{path.relative_to(ROOT)}:{name}"
        for path in sorted(ROOT.rglob("*.py"))
        for name, n in parameter_counts(path).items()
        if n > 8
    }
    assert found == set(MANY_PARAMETERS)


def test_the_orchestrator_is_short_and_the_stages_take_few_parameters():
    """round_mesh reads in one screen (under 80 lines with its docstring), and no function of
    the pipeline takes more than 8 parameters (state travels in Job, VertexState and the
    stages' results). Not vacuous: the scan counts the command line's round (its options)."""
    assert parameter_counts(ROOT / "cli.py")["round_cmd"] > 8
    tree = ast.parse((ROOT / "design.py").read_text(encoding="utf-8"))
    (orchestrator,) = [n for n in tree.body if getattr(n, "name", "") == "round_mesh"]
    assert orchestrator.end_lineno - orchestrator.lineno + 1 < 80
    many = {
        f"{path}:{name}": n
        for path in PIPELINE
        for name, n in parameter_counts(ROOT / path).items()
        if n > 8
    }
    assert many == {}
