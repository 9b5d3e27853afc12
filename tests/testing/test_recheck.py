"""The independent re-check of design.fold (filletfold.testing.recheck, issue 26).

Real meshes are left out of the asserted list (5-9 s each; at the time of writing their cone
facets were folded by up to 76 degrees, more than the arc step): examples/bunny-lowres.obj,
tests/data/corpus/pyvista-nut.ply, tests/data/corpus/compas-tubemesh.obj.
"""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest

from filletfold.cli import main as cli_main
from filletfold.testing.recheck import chord_share, main, recheck_fold

#: Built-in examples whose default design passes the re-check today.
PASSING = [
    ("icosahedron",),
    ("cube",),
    ("torus",),
    ("blob",),
    ("l-prism",),
    ("miura", "--material-loss"),
]


def _round(tmp, mesh, *options):
    code = cli_main(["round", mesh, *options, "-o", str(tmp), "-q"])
    assert code == 0
    return tmp


@pytest.fixture(scope="module")
def ico(tmp_path_factory):
    return _round(tmp_path_factory.mktemp("ico") / "design", "icosahedron")


@pytest.mark.parametrize("args", PASSING, ids=lambda a: " ".join(a))
def test_builtin_examples_pass(args, tmp_path, ico):
    folder = ico if args == ("icosahedron",) else _round(tmp_path / "d", *args)
    r = recheck_fold(folder, args[0])
    assert r["ok"], r["failures"]
    assert r["arc_step_deg"] == 10.0 and r["arc_step_source"].startswith("report.json")
    assert r["limits"]["edge_mismatch"] == pytest.approx(5.07e-3, rel=1e-2)  # 2 steps' chord
    assert r["worst_facet_fold_deg"] <= 10.0 + 1e-6
    assert r["worst_edge_mismatch"] <= chord_share(10.0) + 1e-9
    assert 0 < r["worst_crease_deg"] <= 179.0
    assert r["mv_sign_errors"] == 0
    assert r["short_edges"] == 0
    if args[0] != "miura":  # closed meshes: the folded form has no border
        assert r["mesh_closed"] is True
        assert r["boundary_edges"] == 0 and r["open_boundary_length"] == 0.0
    else:
        assert r["mesh_closed"] is False and r["boundary_edges"] > 0


def test_chord_share():
    assert chord_share(0) == 0.0
    assert chord_share(10.0) == pytest.approx(1.26876e-3, rel=1e-4)
    t = math.radians(10.0)
    assert chord_share(10.0) == pytest.approx(1 - 2 * math.sin(t / 2) / t)


def _load(folder):
    return json.loads((folder / "design.fold").read_text())


def _write(doc, src, tmp_path):
    out = tmp_path / "broken"
    out.mkdir()
    (out / "design.fold").write_text(json.dumps(doc))
    shutil.copy(src / "report.json", out / "report.json")
    return out


def _edge_faces(doc):
    """{sorted edge: [faces]} of the key frame."""
    ef: dict = {}
    for f, face in enumerate(doc["faces_vertices"]):
        for a, b in zip(face, face[1:] + face[:1], strict=True):
            ef.setdefault((min(a, b), max(a, b)), []).append(f)
    return ef


def _rotate(p, a, b, deg):
    """``p`` turned by ``deg`` about the line through ``a`` and ``b`` (Rodrigues)."""
    k = (b - a) / np.linalg.norm(b - a)
    v = p - a
    t = math.radians(deg)
    return a + v * math.cos(t) + np.cross(k, v) * math.sin(t) + k * (k @ v) * (1 - math.cos(t))


def test_facet_folded_30_degrees_is_named(ico, tmp_path):
    doc = _load(ico)
    ef = _edge_faces(doc)
    faces = doc["faces_vertices"]
    patch = doc["filletfold:faces_patch"]
    # an F edge between two triangles of a cone fan
    e = next(
        i
        for i, ((u, v), a) in enumerate(
            zip(doc["edges_vertices"], doc["edges_assignment"], strict=True)
        )
        if a == "F"
        and all(
            len(faces[f]) == 3 and patch[f].startswith("cone") for f in ef[(min(u, v), max(u, v))]
        )
    )
    u, v = doc["edges_vertices"][e]
    fb = ef[(min(u, v), max(u, v))][1]
    (w,) = set(faces[fb]) - {u, v}
    x3 = np.array(doc["file_frames"][0]["vertices_coords"], dtype=float)
    x3[w] = _rotate(x3[w], x3[u], x3[v], 30.0)  # keeps w's distances to u and v
    doc["file_frames"][0]["vertices_coords"] = x3.tolist()
    r = recheck_fold(_write(doc, ico, tmp_path), "icosahedron")
    assert not r["ok"]
    assert r["worst_facet_fold_deg"] > 25
    line = next(s for s in r["failures"] if s.startswith(f"edge {e} (F, cone"))
    assert "folded" in line and "> arc step 10°" in line
    assert main([str(tmp_path / "broken")]) == 1


def test_pattern_edge_stretched_1_percent_is_named(ico, tmp_path, capsys):
    doc = _load(ico)
    x2 = np.array(doc["vertices_coords"], dtype=float)
    # the longest M edge: move its first end 1 % of its length toward the second in 2D, so
    # that the folded edge is 1 % longer than the flat one
    length = [
        np.linalg.norm(x2[b] - x2[a]) if s == "M" else 0.0
        for (a, b), s in zip(doc["edges_vertices"], doc["edges_assignment"], strict=True)
    ]
    e = int(np.argmax(length))
    a, b = doc["edges_vertices"][e]
    x2[a] += 0.01 * (x2[b] - x2[a])
    doc["vertices_coords"] = x2.tolist()
    r = recheck_fold(_write(doc, ico, tmp_path), "icosahedron")
    assert not r["ok"]
    assert r["worst_stretch"] == pytest.approx(1 / 0.99 - 1, rel=1e-6)
    assert r["worst_stretch_at"]["edge"] == e
    line = next(s for s in r["failures"] if s.startswith(f"edge {e} (M, "))
    assert "stretched 1.01%" in line
    assert main([str(tmp_path / "broken" / "design.fold")]) == 1
    assert json.loads(capsys.readouterr().out)["ok"] is False


def test_arc_step_argument_and_unreadable(ico, tmp_path, capsys):
    r = recheck_fold(ico / "design.fold", arc_step_deg=1.0)  # tighter than the design's 10
    assert r["arc_step_source"] == "argument" and not r["ok"]
    assert any("> arc step 1°" in s for s in r["failures"])
    assert r["mesh_closed"] is True and r["mesh_closed_source"].startswith("design.fold mesh")
    (tmp_path / "x.fold").write_text("{}")
    assert main([str(tmp_path / "x.fold")]) == 2
    assert main([str(ico), "icosahedron"]) == 0
    capsys.readouterr()


def test_a_mesh_with_an_edge_of_four_faces_is_not_closed():
    """Two tetrahedra sharing an edge: no border, but an edge of four faces is no closed sheet
    (trimesh does not call it watertight either), so its folded form may have a border."""
    from filletfold.testing.recheck import _closed_by_edge_count

    tet = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]
    assert _closed_by_edge_count(tet)
    other = [[a if a < 2 else a + 2 for a in f] for f in tet]  # vertices 0, 1, 4, 5
    assert not _closed_by_edge_count(tet + other)
