"""The default outputs' size per input vertex (issue 27's budget is 5 KB): counts of bytes, a
ratchet that fails when a change writes more per vertex than the design needs (per-element
data written twice, digits the numbers do not carry, facet lines in the cut file)."""

from __future__ import annotations

import filletfold

#: Bytes per input vertex of the default files of the built-in blob (162 vertices, modules):
#: 18.1 KB when this test was written (design.fold 8.0, pattern.svg 4.9, annotations.json
#: 2.8, folded.obj 2.1, the rest 0.2); labels with the digits of their placement took
#: annotations.json to 2.3 (total 17.6); a label's class and size on its run's group, not
#: on each label, pattern.svg to 4.3 (total 17.0).
BLOB_BUDGET = {
    "design.fold": 8_500,
    "pattern.svg": 4_500,
    "annotations.json": 2_450,
    "folded.obj": 2_300,
    "total": 17_800,
}


def test_default_outputs_stay_within_their_budget_per_vertex(tmp_path):
    design = filletfold.round_mesh("blob")
    design.export(tmp_path)
    n = design.mesh.n_vertices
    sizes = {f.name: f.stat().st_size for f in tmp_path.iterdir() if f.is_file()}
    per_vertex = {name: size / n for name, size in sizes.items()}
    per_vertex["total"] = sum(sizes.values()) / n
    over = {k: round(per_vertex[k]) for k, v in BLOB_BUDGET.items() if per_vertex[k] > v}
    assert not over, f"bytes per input vertex over budget: {over} (budget {BLOB_BUDGET})"
    svg = (tmp_path / "pattern.svg").read_text()
    assert "#ffff00" not in svg and "<line x1" not in svg.split('id="tab-hinge"')[0]
