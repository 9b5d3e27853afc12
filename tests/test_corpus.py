"""The default command on real meshes (tests/data/corpus, see its SOURCES.md): what a user gets.

Every mesh gives a design whose certificate holds, which the independent re-check of its
``design.fold`` against the input mesh (:mod:`filletfold.testing.recheck`) passes too, and
whose folded surface has no hole (every vertex a cone or kept sharp), or a one-line error that
names a defect no tool could repair; never a traceback. ``benchmarks/corpus.py`` prints the
same for a larger corpus fetched from PyPI as a table (repairs, radii fitted, vertices per
status, time, peak memory, worst facet fold and edge mismatch).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from filletfold.cli import main
from filletfold.testing.recheck import recheck_fold

CORPUS = Path(__file__).parent / "data" / "corpus"
MESHES = sorted(p.name for p in CORPUS.iterdir() if p.suffix.lower() in (".obj", ".ply", ".stl"))
#: Meshes no tool could make a surface of, and what the error says.
REFUSED = {"compas-saddle.obj": "the file has 96 vertices but no faces"}
#: The meshes that take more than about 3 s here: the slow tier (`make test-slow`) runs them,
#: `make test` the rest.
SLOW = {
    "compas-tubemesh.obj",
    "geometry-central-bob_small.ply",
    "geometry-central-fox.ply",
    "meshio-bun_zipper_res4.ply",
    "meshio-elephav.obj",
    "openmesh-sphere840.ply",
    "pyvista-airplane.ply",
    "pyvista-ant.ply",
    "pyvista-nut.ply",
    "pyvista-sphere.ply",
}
CASES = [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in MESHES]


def test_the_corpus_has_its_sources_and_licences():
    sources = (CORPUS / "SOURCES.md").read_text()
    assert len(MESHES) >= 26
    for name in MESHES:
        assert f"`{name}`" in sources, f"{name} is not in SOURCES.md"
    for package in ("compas", "pyvista", "openmesh", "geometry-central", "happly", "meshio"):
        assert (CORPUS / f"LICENSE-{package}.txt").is_file(), package


def test_the_fast_tier_keeps_a_real_subset():
    assert SLOW <= set(MESHES)
    assert len(set(MESHES) - SLOW) >= 15


@pytest.mark.parametrize("name", CASES)
def test_default_command_gives_a_valid_design_or_one_line(name, tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["round", str(CORPUS / name), "-o", str(out), "-q"])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if name in REFUSED:
        assert code == 2 and not out.exists()
        assert err.strip().splitlines() == [f"error: {CORPUS / name}: {REFUSED[name]}"]
        return
    assert code == 0, err
    report = json.loads((out / "report.json").read_text())
    failed = [k for k, v in report["certificate"]["checks"].items() if not v["ok"]]
    assert report["certificate"]["ok"], f"{name}: certificate fails {failed}"
    assert main(["check", str(out)]) == 0  # from the files alone, too
    # and re-checked from design.fold and the input mesh alone, by code that shares none of
    # the certificate's: no F edge folded past the arc step, every edge's lengths, M/V, the
    # folded form closed wherever the input is
    again = recheck_fold(out, CORPUS / name)
    assert again["ok"], f"{name}: the re-check fails: {again['failures'][:3]}"
    counts = report["status_counts"]
    assert counts["ok"] + counts["boundary"] + counts["sharp"] > 0
    # no holes (issue 15): every vertex has a cone or keeps its corner, the folded surface has
    # the mesh's boundary loops and its border runs along the mesh's boundary edges
    assert report["treatment_counts"]["hole"] == 0, f"{name}: {report['treatment_counts']}"
    holes = report["certificate"]["checks"]["holes"]
    assert holes["value"] == 0 and " 0 notches" in holes["detail"], holes["detail"]
    notch = re.search(r"deepest notch of the border / size ([0-9.e+-]+)", holes["detail"])
    assert notch is None or float(notch.group(1)) <= 1e-9, holes["detail"]
