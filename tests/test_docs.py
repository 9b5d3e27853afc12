"""docs/method.md names functions that exist, the code cites it, not outside notes, and the
README tree and the package docstrings name every module."""

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


STAGES = ("mesh", "rounding", "vertex", "surface", "layout")


def _readme_tree() -> dict[str, str]:
    """The README's package tree ("What it computes"): folder -> its text."""
    text = (ROOT / "README.md").read_text()
    block = text.split("```\nsrc/filletfold/\n", 1)[1].split("```", 1)[0]
    tree, folder = {}, None
    for line in block.splitlines():
        m = re.match(r"  (\w+)/\s", line)
        if m:
            folder = m.group(1)
            tree[folder] = ""
        tree[folder] += " " + line
    return tree


def test_the_readme_tree_and_the_package_docstrings_name_every_module():
    tree = _readme_tree()
    assert set(STAGES) <= set(tree)
    for stage in STAGES:
        folder = ROOT / "src" / "filletfold" / stage
        modules = sorted(p.stem for p in folder.glob("*.py") if p.stem != "__init__")
        doc = importlib.import_module(f"filletfold.{stage}").__doc__
        for name in modules:
            assert re.search(rf"\b{name}\b", tree[stage]), f"README tree lacks {stage}/{name}"
            assert f":mod:`.{name}`" in doc, f"filletfold.{stage}'s docstring lacks {name}"
