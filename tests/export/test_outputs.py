"""What a design writes (:mod:`filletfold.export.outputs`): the report's content and keys (as
the README lists them), timings apart, the summary, and the files of export_design."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from filletfold.export.outputs import (
    FITTING_TABLES,
    OUTPUT_FILES,
    REPORT_TABLES,
    design_report,
    design_summary,
    edge_mismatch,
    export_design,
    timings_json,
)

from ..conftest import design_of

README = Path(__file__).resolve().parents[2] / "README.md"


def test_every_top_level_report_key_is_in_the_readme():
    report = design_report(design_of("cube"))
    text = README.read_text(encoding="utf-8")
    documented = text[text.index("* `report.json`") : text.index("* `timings.json`")]
    for key in report:
        assert f"`{key}`" in documented, key
    assert "timings" not in report  # timings.json: the report has the same bytes every run


def test_the_report_is_the_design():
    d = design_of("torus")
    r = design_report(d)
    assert r["status_counts"] == d.status_counts()
    assert len(r["vertices"]) == d.mesh.n_vertices and len(r["edges"]) == d.mesh.n_edges
    assert [v["status"] for v in r["vertices"]] == list(d.vertices.status)
    np.testing.assert_allclose([e["radius"] for e in r["edges"]], d.rounding.radius)
    assert r["pattern"]["max_edge_mismatch"] == pytest.approx(float(edge_mismatch(d.pattern).max()))
    json.dumps(r, allow_nan=False)  # plain JSON: no NaN, no numpy types


def test_timings_are_seconds_per_stage():
    d = design_of("cube")
    t = json.loads(timings_json(d))
    assert {"read", "rounding", "normals", "apices", "surface", "total"} <= set(t)
    assert all(isinstance(v, float) and v >= 0 for v in t.values())


def test_the_summary_counts_the_vertices():
    d = design_of("torus")
    text = design_summary(d)
    for status, count in d.status_counts().items():
        if count:
            assert re.search(rf"\b{count} {status}\b", text), status


def test_export_design_writes_the_default_files(tmp_path):
    d = design_of("cube")
    written = export_design(d, tmp_path / "out")
    names = sorted(p.name for p in written)
    assert set(OUTPUT_FILES) <= set(names)
    for p in written:
        assert p.stat().st_size > 0
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    full = json.loads(json.dumps(design_report(d)))
    summary = {k: v for k, v in full.items() if k not in REPORT_TABLES}  # a summary, and its
    summary["fitting"] = {  # fitting has the counts of the per-element lists, not the lists
        k: v for k, v in full["fitting"].items() if k not in FITTING_TABLES
    }
    assert report == summary
    assert report["mesh_counts"] == {"vertices": 8, "edges": 12, "faces": 6}
    assert report["treatment_counts"] == {"cone": 8, "sharp": 0, "hole": 0}
    # the tables on request; the mesh's data in design.fold either way
    export_design(d, tmp_path / "tables", formats="fold,json", tables=True)
    assert json.loads((tmp_path / "tables" / "report.json").read_text()) == full
    fold = json.loads((tmp_path / "out" / "design.fold").read_text())
    np.testing.assert_allclose(fold["filletfold:mesh_vertices_coords"], d.mesh.vertices)
    np.testing.assert_allclose(fold["filletfold:mesh_edges_radius"], d.rounding.radius)
    assert fold["filletfold:mesh_edges_vertices"] == d.mesh.edges.tolist()
    apex = [v["apex"] for v in full["vertices"]]
    np.testing.assert_allclose(fold["filletfold:mesh_vertices_apex"], apex, rtol=1e-11)
