"""Layering: the library never imports its front ends.

Geometry lives in the library; the browser app (:mod:`filletfold.app`) and the command line
(:mod:`filletfold.cli`) only parse, call and display. So no other module imports
``filletfold.app`` -- at the top or inside a function -- and in particular no writer under
:mod:`filletfold.export`. Read from the source with :mod:`ast`, so an import that only runs on
some path is seen too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import filletfold

ROOT = Path(filletfold.__file__).parent
#: The front ends: they may import the app.
FRONT_ENDS = ("filletfold.app", "filletfold.cli")


def module_name(path: Path) -> str:
    """``filletfold.export.png`` for ``.../filletfold/export/png.py`` (a package: its name)."""
    parts = ("filletfold", *path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path) -> set[str]:
    """Absolute names of every module ``path`` imports, anywhere in the file (relative imports
    resolved; ``from a import b`` counts as ``a`` and as ``a.b``, ``b`` may be a module)."""
    name = module_name(path)
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
