"""docs/method.md names functions that exist, and the code cites it, not outside notes."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
METHOD = ROOT / "docs" / "method.md"
#: Notes outside the repository that code once cited (spelt in two parts, so that this file
#: does not cite them either).
OUTSIDE = ("METHOD" + "-NOTES", "../" + "shared")


def _resolve(dotted: str):
    """The object ``filletfold.<dotted>`` (module path, then attributes), or None."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module("filletfold." + ".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            obj = getattr(obj, name, None)
        return obj
    return None


def test_every_function_of_the_equation_table_exists():
    text = METHOD.read_text(encoding="utf-8")
    table = text[text.index("## Equations and functions") :]
    named = []
    for row in table.splitlines():
        if not row.startswith("|"):
            continue
        module = None  # the last cell: `path.py: name`, then further `name`s of that module
        for token in re.findall(r"`([^`]+)`", row.rstrip(" |").rsplit("|", 1)[-1]):
            if ".py: " in token:
                path, token = token.split(".py: ")
                module = path.replace("/", ".")
            if module is not None and re.fullmatch(r"[\w.]+", token):
                named.append(f"{module}.{token}")
    assert len(named) >= 25
    missing = [n for n in named if _resolve(n) is None]
    assert not missing, missing


def test_the_pipeline_names_functions_that_exist():
    text = METHOD.read_text(encoding="utf-8")
    pipeline = text[text.index("## Pipeline") : text.index("## Conventions")]
    stages = "mesh|rounding|vertex|surface|layout|export|design|check"
    files = ("py", "fold", "json", "obj", "svg", "png")
    found = re.findall(rf"`((?:{stages})\.[\w.]+)`", pipeline)
    named = [n for n in found if n.split(".")[-1] not in files]
    assert len(named) >= 20
    missing = [n for n in named if _resolve(n) is None]
    assert not missing, missing


def test_code_cites_the_docs_not_outside_notes():
    hits = []
    paths = [ROOT / "README.md"]
    for folder in ("src", "tests", "benchmarks"):
        paths += sorted((ROOT / folder).rglob("*.py"))
    for path in paths:
        text = path.read_text(encoding="utf-8")
        if any(word in text for word in OUTSIDE):
            hits.append(str(path.relative_to(ROOT)))
    assert not hits, hits
